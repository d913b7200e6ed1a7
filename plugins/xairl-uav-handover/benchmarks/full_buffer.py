"""Why the DQN hands over with a full buffer: what the buffer did before each of its handovers, and whether a
handover from a full buffer could have helped (issue 26, target 4).

On held-out flights flown by a DQN, at every decision it records the buffer, the serving cell's uplink capacity
and each candidate's (the simulator knows them; the DQN sees only the buffer). It prints: the share of handovers
taken with a full buffer; for those, the buffer at the decision before (full: the DQN waited; partial or empty: it
filled within one decision period) and how many decisions it had already been full; what precedes the onset of a
full buffer; how often a partial buffer is full at the next decision; and, in full-buffer states, how often the
serving uplink is below the video rate and some candidate's is above it (a handover could help).

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/full_buffer.py [--checkpoint PATH] [--flights 200]
"""

import argparse

import numpy as np
import torch

from xairl_uav_handover.env import HandoverVecEnv
from xairl_uav_handover.evaluate import HELD_OUT_SEED
from xairl_uav_handover.features import BUFFER
from xairl_uav_handover.policy import DQNController, load_checkpoint
from xairl_uav_handover.uplink import capacity_bps, sinr_db


def fly(ckpt, n_flights: int):
    """Per decision (time, flight): buffer, handover taken, uplink capacity of each candidate (NaN: empty slot)."""
    cfg, dqn = ckpt.sim_config, DQNController(ckpt.net)
    env = HandoverVecEnv(cfg, n_flights)
    env.reset(seed=HELD_OUT_SEED)
    queue, handover, caps, ended = [], [], [], False
    while not ended:
        sim, k = env.sim, np.arange(n_flights)
        cells = np.where(env.candidates < 0, sim.serving[:, None], env.candidates)
        loss = sim.loss_db[k[:, None], cells] - sim._gain  # the same antenna both ways, as Simulator.ul_sinr_db
        cap = capacity_bps(cfg, sinr_db(cfg, loss, sim._ul_interference[k[:, None], cells]))
        caps.append(np.where(env.candidates < 0, np.nan, cap))
        queue.append(env.obs[:, BUFFER].copy())
        *_, truncated, info = env.step(dqn(env))
        handover.append(info["handover"] > 0)
        ended = bool(truncated.all())
    return np.array(queue), np.array(handover), np.array(caps)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--checkpoint", default=None, help="a DQN checkpoint (default: the committed one)")
    ap.add_argument("--flights", type=int, default=200, help="held-out flights (evaluation seed 0)")
    args = ap.parse_args()
    torch.set_num_threads(1)
    ckpt = load_checkpoint(args.checkpoint)
    b = ckpt.sim_config.buffer
    q, ho, caps = fly(ckpt, args.flights)
    full, video = q >= b.q_max_bits, b.video_rate_mbps * 1e6
    partial = (q > 0) & ~full
    from_full = ho[1:] & full[1:]
    before = q[:-1][from_full]
    waited = [full_run(full[t::-1, k]) for t, k in zip(*np.nonzero(from_full))]
    onset = q[:-1][full[1:] & ~full[:-1]]
    share = lambda x: f"{100 * np.mean(x):.1f} %"  # noqa: E731
    print(
        f"{args.flights} held-out flights, {int(ho.sum())} handovers; with a full buffer: {share(full[ho])}, "
        f"partial: {share(partial[ho])}, empty: {share(q[ho] == 0)}"
    )
    print(
        f"full-buffer handovers, the decision before: full {share(before >= b.q_max_bits)}, partial "
        f"{share((before > 0) & (before < b.q_max_bits))}, empty {share(before == 0)}; decisions already full "
        f"before them: median {np.median(waited):.0f}, 90th percentile {np.percentile(waited, 90):.0f}"
    )
    print(
        f"onsets of a full buffer preceded by a partial one: {share(onset > 0)}; a partial buffer full at the next "
        f"decision: {share(full[1:][partial[:-1]])}, empty: {share(q[1:][partial[:-1]] == 0)}"
    )
    print(
        f"full-buffer states: {share(full)} of decisions; serving uplink below the video rate in "
        f"{share(caps[full, 0] < video)}; some candidate above it in {share(np.nanmax(caps[full][:, 1:], 1, initial=0) > video)}; "
        f"the DQN hands over in {share(ho[full])} of them, to a cell above it in {share(target_ok(caps, ho & full, video))}"
    )


def full_run(backwards: np.ndarray) -> int:
    """Decisions in a row with a full buffer, counted back from the first of ``backwards``."""
    return len(backwards) if backwards.all() else int(np.argmin(backwards))


def target_ok(caps, mask, video: float) -> np.ndarray:
    """Whether the cell each masked handover went to carried the video at the next decision (candidate 0 there is
    the cell handed over to)."""
    t, k = np.nonzero(mask[:-1])
    return caps[t + 1, k, 0] > video


if __name__ == "__main__":
    main()
