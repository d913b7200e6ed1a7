"""Calibration of the simulator (issue 11, WIP): for config overrides given as JSON, CHM handovers per minute,
median uplink capacity, buffer non-empty / full shares and detected-neighbour counts on 100 simulated flights.
Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/calibrate_sim.py '{"radio.ul_activity": 0.08}' ...
"""
import json
import sys

import numpy as np
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.env import HandoverVecEnv
from xairl_uav_handover.baselines import CHM
from xairl_uav_handover import uplink
def run(over, n=100, secs=60):
    base = SimConfig().model_dump()
    for k, v in over.items():
        a, b = k.split("."); base[a][b] = v
    cfg = SimConfig.model_validate(base)
    env = HandoverVecEnv(cfg, n, decision_every=1); env.reset(seed=1); chm = CHM(); chm.reset(env)
    s=[]; q=[]; ne=[]; hos=0
    for i in range(int(secs/0.04)):
        *_, info = env.step(chm(env)); hos += info["handover"].sum()
        if i % 25 == 0: s.append(env.sim.ul_sinr_db().copy()); q.append(env.sim.q.copy()); ne.append((env.candidates[:,1:]>=0).sum(1))
    s=np.concatenate(s); q=np.concatenate(q); ne=np.concatenate(ne)
    cap=np.median(uplink.capacity_bps(cfg, s))/1e6
    return dict(cap=round(cap,1), ne=round((q>0).mean(),3), full=round((q>=cfg.buffer.q_max_bits*.999).mean(),3), chm=round(hos/n/(secs/60),2), nb_lt3=round((ne<3).mean(),2), nb_med=float(np.median(ne)))
for arg in sys.argv[1:]:
    over = json.loads(arg); print(over, run(over))
