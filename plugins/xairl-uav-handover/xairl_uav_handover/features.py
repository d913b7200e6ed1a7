"""The DQN's state layout (as in the paper) and what each feature means, for plots and narration.

:func:`state_rows` is the one place that lays a state out; the simulator and the real-flight replay build states
through it, and code that reads a state uses :data:`FEATURES` or the column slice below.
"""
import numpy as np

from xairl import Comparison, DomainFacts, FeatureInfo

N_CANDIDATES = 4  # candidate 0 is the serving BS (stay); 1..3 the strongest other BSs
FEATURES = ("x", "y", "z", "buffer_queue_size", "serving_bs",
            *(f"rsrp_{k}" for k in range(N_CANDIDATES)), *(f"rsrq_{k}" for k in range(N_CANDIDATES)))
RSRP = slice(5, 5 + N_CANDIDATES)  # the candidates' RSRP columns, serving BS first
RSRQ = slice(5 + N_CANDIDATES, 5 + 2 * N_CANDIDATES)  # and their RSRQ columns
#: action k: associate with candidate k; candidate 0 is the serving BS, so action 0 is "stay"
ACTIONS = ("stay", *(f"handover_to_candidate_{k}" for k in range(1, N_CANDIDATES)))
#: words followed by an identifier in this plugin's narratives ("BS 15", "candidate 2"), not by a quantity
LABEL_WORDS = ("BS", "candidate")


def state_rows(position, queue_bits, serving_id, rsrp, rsrq, observation) -> np.ndarray:
    """States (K, 13) float32 in :data:`FEATURES` order, as the UE reports them (``ObservationConfig``): x, y
    quantised to ``position_grid_m`` when it is set; an empty candidate slot (NaN) reported at the detection limit.

    :param position: (K, 3) x, y, z in metres: x east and y north of the centre of the area the UAVs fly in (the
        grid's centre site in simulation, the campaign area's centre for real flights); ``queue_bits`` (K,);
        ``serving_id`` (K,) the serving BS's id.
    :param rsrp: (K, 4) dBm of the candidates (serving first), NaN where no neighbour is measured; ``rsrq`` (K, 4) dB.
    """
    position = np.array(position, dtype=float).reshape(-1, 3)
    k = len(position)
    if observation.position_grid_m > 0:
        position[:, :2] = np.round(position[:, :2] / observation.position_grid_m) * observation.position_grid_m
    rsrp = np.array(rsrp, dtype=float).reshape(k, N_CANDIDATES)
    rsrq = np.array(rsrq, dtype=float).reshape(k, N_CANDIDATES)
    empty = np.isnan(rsrp) | np.isnan(rsrq)
    limit = observation.detection_rsrq_db
    # both cells' RSRQ share one RSSI, so RSRP differs by the RSRQ difference: the slot sits exactly at the limit
    rsrp = np.where(empty, rsrp[:, :1] + limit - rsrq[:, :1], rsrp)
    rsrq = np.where(empty, limit, rsrq)
    return np.concatenate([position, np.reshape(queue_bits, (k, 1)), np.reshape(serving_id, (k, 1)), rsrp, rsrq],
                          axis=1).astype(np.float32)


def available_actions(states, observation) -> np.ndarray:
    """Bool (n, 4): stay is always available, a handover only to a measured candidate (an empty slot reads exactly
    at the detection limit; a measured neighbour is strictly above it)."""
    rsrq = np.asarray(states, dtype=np.float32).reshape(-1, len(FEATURES))[:, RSRQ]
    mask = rsrq > np.float32(observation.detection_rsrq_db)
    mask[:, 0] = True
    return mask


GROUPS = {"position": ("x", "y", "z"), "rsrp": ("rsrp_0", "rsrp_1", "rsrp_2", "rsrp_3"),
          "rsrq": ("rsrq_0", "rsrq_1", "rsrq_2", "rsrq_3")}


_WHO = ("the serving BS", "the strongest neighbour", "the second strongest neighbour", "the third strongest neighbour")


def _signal(kind: str, k: int, unit: str, low: str, high: str) -> FeatureInfo:
    aliases = (f"{kind} of candidate {k}", f"candidate {k}'s {kind}") if k else (f"serving {kind}",)
    return FeatureInfo(unit, f"{_WHO[k]}'s {kind}", low, high, aliases)


FEATURE_INFO = {
    "x": FeatureInfo("m", "the UAV's east position", "west", "east"),
    "y": FeatureInfo("m", "the UAV's north position", "south", "north"),
    "z": FeatureInfo("m", "the UAV's altitude", "low altitude", "high altitude"),
    "buffer_queue_size": FeatureInfo("bit", "the uplink buffer queue", "nearly empty buffer", "nearly full buffer"),
    "serving_bs": FeatureInfo("", "the serving BS's id", "low id", "high id"),
    **{f"rsrp_{k}": _signal("RSRP", k, "dBm", "weak signal", "strong signal") for k in range(4)},
    **{f"rsrq_{k}": _signal("RSRQ", k, "dB", "poor quality", "good quality") for k in range(4)},
}
ACTION_ALIASES = {"stay": ("keep the serving BS", "staying"),
                  **{a: (f"hand over to candidate {k}", f"a handover to candidate {k}")
                     for k, a in enumerate(ACTIONS) if k}}


def handover_facts(state, chosen: int, runner_up: int) -> DomainFacts:
    """Domain facts for narration: stay or hand over, from which BS to which candidate, and how the target (or the
    runner-up candidate, when the UAV stays) compares with the serving BS in RSRP. (Its RSRQ differs by exactly
    the same dB: both cells' RSRQ share one RSSI, so an RSRQ comparison would only repeat it.)"""
    s = dict(zip(FEATURES, (float(v) for v in state)))
    k = chosen if chosen else runner_up
    extras = {"decision": "hand over" if chosen else "stay", "serving_bs": int(round(s["serving_bs"])),
              "target_candidate": int(chosen), "compared_candidate": int(k)}
    comparisons = []
    if k:
        diff = s[f"rsrp_{k}"] - s["rsrp_0"]
        comparisons.append(Comparison(f"{_WHO[k]}'s RSRP was {abs(diff):.1f} dB {'above' if diff >= 0 else 'below'} "
                                      "the serving BS's RSRP", round(abs(diff), 1), "dB"))
    return DomainFacts(extras, tuple(comparisons))
