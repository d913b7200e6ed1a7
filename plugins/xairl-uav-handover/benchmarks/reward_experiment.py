"""Short DQN training under config and training overrides (issue 11 reward experiments, WIP): Table I summary
and the rank of buffer_queue_size by mean |margin contribution|.
Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/reward_experiment.py '{"reward.w_rsrq": 0}' '{"episodes": 20}'
"""
import sys, json, time, numpy as np, warnings
warnings.filterwarnings("ignore")
import xairl
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.train import TrainConfig, train
from xairl_uav_handover.policy import Checkpoint, DQNController, uav_policy, background_states, dqn_decision_states
from xairl_uav_handover.evaluate import table_one
from xairl_uav_handover.baselines import CHM, SAMRO
from xairl_uav_handover.features import FEATURES
from pathlib import Path
sim_over, tc_over = json.loads(sys.argv[1]), json.loads(sys.argv[2])
base = SimConfig().model_dump()
for k, v in sim_over.items():
    a, b = k.split("."); base[a][b] = v
cfg = SimConfig.model_validate(base)
t = time.time()
net, hist = train(TrainConfig(**tc_over), cfg, progress=False)
ck = Checkpoint(Path("x"), net, {}, cfg)
rows = table_one([CHM(), SAMRO(), DQNController(net)], cfg, 100, 0)
exp = xairl.explain(uav_policy(ck), dqn_decision_states(ck, 300, 1), background=background_states(100, 7, cfg))
imp = np.abs(exp.margin()).mean(0); order = [FEATURES[j] for j in np.argsort(-imp)]
print(sys.argv[1], sys.argv[2], f"{time.time()-t:.0f}s", {n: (r["handovers_median"], round(r["pingpong_pct_pooled"],1), round(r["buffer_nonempty_pct_mean"],1), round(r["lost_data_kbit_mean"])) for n, r in rows.items()}, "rank", order.index("buffer_queue_size")+1, order[:4], flush=True)
