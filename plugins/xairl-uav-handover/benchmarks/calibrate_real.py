"""Real UKM states against the simulated training distribution (issue 11, WIP): per-feature p5/50/95, the share
of real states outside the simulated 0.5-99.5 % range, and the modelled real buffer. Argument: config overrides (JSON).
Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/calibrate_real.py '{"radio.gain_spread_db": 8}'
"""
import sys, json, time, numpy as np
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.real_data import load_folder, walk, agreement
from xairl_uav_handover.baselines import CHMOnSamples, SAMROOnSamples
from xairl_uav_handover.policy import background_states
from xairl_uav_handover.features import FEATURES
over = json.loads(sys.argv[1]) if len(sys.argv) > 1 else {}
base = SimConfig().model_dump()
for k, v in over.items():
    a, b = k.split("."); base[a][b] = v
cfg = SimConfig.model_validate(base)
fl,_ = load_folder("/work/shared/data/ukm-uav-lte/raw")
t=time.time(); ws = [walk(f, cfg) for f in fl]; print("walk s", round(time.time()-t,1))
mins = sum((w.t[-1]-w.t[0])/60 for w in ws)
print("live HO/min", round(sum(f.observed_handovers for f in fl)/mins, 2))
cellsets = {id(w): sorted(set(c for cc in w.candidates for c in cc)) for w in ws}
R = np.concatenate([w.states for w in ws]); q = np.concatenate([w.queue_bits for w in ws])
print("real buffer full", (q >= cfg.buffer.q_max_bits*.999).mean(), "nonempty", (q>0).mean())
from xairl_uav_handover.env import HandoverVecEnv
from xairl_uav_handover.baselines import CHM
env = HandoverVecEnv(cfg, 300, decision_every=5); env.reset(seed=3); chm=CHM(); chm.reset(env)
S=[]; tr=np.zeros(1,bool); i=0
while not tr.all():
    obs, *_, tr, info = env.step(np.zeros(300,int)); i+=1
    if i % 10 == 0: S.append(obs)
S=np.concatenate(S)
lo, hi = np.percentile(S, 0.5, axis=0), np.percentile(S, 99.5, axis=0)
out = (R < lo) | (R > hi); print("any out", out.any(1).mean())
for j,f in enumerate(FEATURES): print(f"{f:18s} sim [{lo[j]:9.1f},{hi[j]:9.1f}] real p5/50/95 {np.percentile(R[:,j],[5,50,95]).round(1)} out {out[:,j].mean():.3f}")
