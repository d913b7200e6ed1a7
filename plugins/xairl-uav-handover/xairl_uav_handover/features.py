"""The DQN's state layout (as in the paper) and what each feature means, for plots and narration.

:func:`state_rows` is the one place that lays a state out; the simulator and the real-flight replay build states
through it, and code that reads a state uses :data:`FEATURES` or the column slice below.
"""

import numpy as np

import xairl
from xairl import FeatureInfo, InputError

N_CANDIDATES = 4  # candidate 0 is the serving BS (stay); 1..3 the strongest other BSs
FEATURES = (
    "x",
    "y",
    "z",
    "buffer_queue_size",
    "serving_bs",
    *(f"rsrp_{k}" for k in range(N_CANDIDATES)),
    *(f"rsrq_{k}" for k in range(N_CANDIDATES)),
)
#: the signals of the DQN with memory (memory.py): the snapshot's features, then seconds on the serving cell and
#: since the last handover, each step of its window
SIGNALS = (*FEATURES, "on_cell_s", "since_handover_s")
#: decisions in its window: 1 s at the DQN's 0.2 s decision period (SimConfig.decision_every x flight.dt_s)
MEMORY_STEPS = 5
RSRP = slice(5, 5 + N_CANDIDATES)  # the candidates' RSRP columns, serving BS first
RSRQ = slice(5 + N_CANDIDATES, 5 + 2 * N_CANDIDATES)  # and their RSRQ columns
BUFFER = FEATURES.index("buffer_queue_size")
#: action k: associate with candidate k; candidate 0 is the serving BS, so action 0 is "stay"
ACTIONS = ("stay", *(f"handover_to_candidate_{k}" for k in range(1, N_CANDIDATES)))
#: words followed by an identifier in this plugin's narratives ("BS 15", "candidate 2"), not by a quantity
LABEL_WORDS = ("BS", "candidate")


def state_rows(position, queue_bits, serving_id, rsrp, rsrq, observation) -> np.ndarray:
    """States (K, 13) float32 in :data:`FEATURES` order, as the UE reports them (``ObservationConfig``): x, y
    quantised to ``position_grid_m`` when it is set (x, y, z all 0 when ``position_hidden``); an empty candidate
    slot (NaN) reported at the detection limit.

    :param position: (K, 3) x, y, z in metres: x east and y north of the centre of the area the UAVs fly in (the
        grid's centre site in simulation, the campaign area's centre for real flights); ``queue_bits`` (K,);
        ``serving_id`` (K,) the serving BS's id.
    :param rsrp: (K, 4) dBm of the candidates (serving first), NaN where no neighbour is measured; ``rsrq`` (K, 4) dB.
    """
    position = np.array(position, dtype=float).reshape(-1, 3)
    k = len(position)
    if observation.position_hidden:
        position[:] = 0.0
    if observation.position_grid_m > 0:
        position[:, :2] = np.round(position[:, :2] / observation.position_grid_m) * observation.position_grid_m
    rsrp = np.array(rsrp, dtype=float).reshape(k, N_CANDIDATES)
    rsrq = np.array(rsrq, dtype=float).reshape(k, N_CANDIDATES)
    empty = np.isnan(rsrp) | np.isnan(rsrq)
    limit = observation.detection_rsrq_db
    # both cells' RSRQ share one RSSI, so RSRP differs by the RSRQ difference: the slot sits exactly at the limit
    rsrp = np.where(empty, rsrp[:, :1] + limit - rsrq[:, :1], rsrp)
    rsrq = np.where(empty, limit, rsrq)
    return np.concatenate(
        [position, np.reshape(queue_bits, (k, 1)), np.reshape(serving_id, (k, 1)), rsrp, rsrq], axis=1
    ).astype(np.float32)


def snapshot(states) -> np.ndarray:
    """The newest observation's :data:`FEATURES` of memory states (n, 75: memory.py); snapshot states (n, 13) as
    they are. What the action mask, the rule baselines and the facts hook read."""
    states = np.asarray(states)
    if states.shape[-1] == len(FEATURES):
        return states
    return states[..., -len(SIGNALS) :][..., : len(FEATURES)]


def available_actions(states, observation) -> np.ndarray:
    """Bool (n, 4): stay is always available, a handover only to a measured candidate (an empty slot reads exactly
    at the detection limit; a measured neighbour is strictly above it)."""
    rsrq = np.asarray(snapshot(states), dtype=np.float32).reshape(-1, len(FEATURES))[:, RSRQ]
    mask = rsrq > np.float32(observation.detection_rsrq_db)
    mask[:, 0] = True
    return mask


def checked_actions(actions, where=lambda k: f"flight {k}") -> np.ndarray:
    """``actions`` as int64 indices, refused with an :class:`xairl.InputError` naming the first one (``where(k)``
    says whose) that is not a whole number in 0..3: a policy's NaN must not be cast to some action."""
    a = np.asarray(actions)
    if a.dtype.kind in "iub":
        ok = (a >= 0) & (a < len(ACTIONS))
    else:
        try:
            f = a.astype(float)
        except (TypeError, ValueError):
            f = np.full(a.shape, np.nan)
        ok = np.isfinite(f) & (f == np.round(f)) & (f >= 0) & (f < len(ACTIONS))
    if not ok.all():
        k = int(np.flatnonzero(~ok.ravel())[0])
        v = a.ravel()[k]
        v = f"{float(v):g}" if np.asarray(v).dtype.kind in "iufb" else repr(v)[:40]
        raise InputError(
            f"the action for {where(k)} is {v}, not one of 0..{len(ACTIONS) - 1} (0 stays, k "
            f"hands over to candidate k); a policy whose output is NaN or out of range cannot act."
        )
    return a.astype(np.int64)


GROUPS = {
    "position": ("x", "y", "z"),
    "rsrp": ("rsrp_0", "rsrp_1", "rsrp_2", "rsrp_3"),
    "rsrq": ("rsrq_0", "rsrq_1", "rsrq_2", "rsrq_3"),
}


_WHO = ("the serving BS", "the strongest neighbour", "the second strongest neighbour", "the third strongest neighbour")
#: level words: RSRP below the reward's violation threshold (-100 dBm, HandoverConfig) is weak, above -80 dBm
#: (LTE's usual "excellent" band) strong; RSRQ below the violation threshold (-16 dB) poor, above -10 dB good
RSRP_LEVELS = (-100.0, -80.0)
RSRQ_LEVELS = (-16.0, -10.0)


def _signal(kind: str, k: int, unit: str, low: str, high: str, levels) -> FeatureInfo:
    aliases = (
        (f"{kind} of candidate {k}", f"candidate {k}'s {kind}")
        if k
        else (f"serving {kind}", f"the serving cell's {kind}", f"serving cell {kind}")
    )
    return FeatureInfo(unit, f"{_WHO[k]}'s {kind}", low, high, aliases, thresholds=levels)


def feature_info(q_max_bits: float = 2e6) -> dict[str, FeatureInfo]:
    """What each feature means to an operator; the buffer's capacity is the simulator's ``q_max_bits``."""
    return {
        "x": FeatureInfo("m", "the UAV's east position", "west", "east"),
        "y": FeatureInfo("m", "the UAV's north position", "south", "north"),
        "z": FeatureInfo("m", "the UAV's altitude", "low altitude", "high altitude"),
        "position": FeatureInfo("", "the UAV's position", kind="group", aliases=("position (x, y, z)",)),
        "buffer_queue_size": FeatureInfo(
            "bit",
            "the uplink buffer",
            "lightly loaded",
            "heavily loaded",
            ("the uplink buffer queue", "buffer queue"),
            capacity=q_max_bits,
        ),
        "serving_bs": FeatureInfo(
            "", "the serving BS's id", aliases=("serving BS", "on BS", "from BS"), kind="identifier"
        ),
        **{f"rsrp_{k}": _signal("RSRP", k, "dBm", "weak signal", "strong signal", RSRP_LEVELS) for k in range(4)},
        **{f"rsrq_{k}": _signal("RSRQ", k, "dB", "poor quality", "good quality", RSRQ_LEVELS) for k in range(4)},
    }


FEATURE_INFO = feature_info()
ACTION_ALIASES = {
    "stay": ("keep the serving BS", "staying"),
    **{
        a: (
            f"hand over to candidate {k}",
            f"a handover to candidate {k}",
            f"switch to candidate {k}",
            "switch cells",
            "change cells",
            "switching",
            "leaving",
        )  # shared by every handover:
        # the chosen one among them
        for k, a in enumerate(ACTIONS)
        if k
    },
}


class HandoverFacts:
    """The UAV plugin's facts hook: what an operator checks beside the DQN's reasons.

    - the decision in cells: stay or hand over, from which BS, to which candidate; the runner-up's candidate;
    - how the compared candidate (the target, or the runner-up when the UAV stays) stands against the serving BS in
      RSRP (its RSRQ differs by exactly the same dB: both cells' RSRQ share one RSSI, so it would only repeat it);
    - what the conventional A3 rule (CHM: the strongest measured neighbour ``offset_db`` above the serving BS for its time-to-trigger)
      would do in the same state, and, given the flight's earlier states, for how many consecutive decisions the
      strongest neighbour has met that condition. A decision period (0.2 s in simulation, a sample in real data)
      is at least the 160 ms time-to-trigger, so two consecutive decisions meeting it mean CHM hands over; one
      means its timer is running;
    - the buffer's fill (% of ``q_max_bits``) and, given history, its trend since the previous decision.
    """

    def __init__(self, q_max_bits: float = 2e6, offset_db: float = 2.0, detection_rsrq_db: float = -24.0):
        self.q_max, self.offset, self.detection = q_max_bits, offset_db, detection_rsrq_db

    def __call__(self, state, chosen: int, runner_up: int, history=None) -> xairl.facts.DomainFacts:
        s = dict(zip(FEATURES, (float(v) for v in state)))
        k = chosen if chosen else runner_up
        fill = 100.0 * s["buffer_queue_size"] / self.q_max
        extras = {
            "decision": "hand over" if chosen else "stay",
            "serving_bs": int(round(s["serving_bs"])),
            "target_candidate": int(chosen),
            "compared_candidate": int(k),
            "runner_up_candidate": int(runner_up),
            "buffer_fill": fill,
            "buffer_trend": "",
        }
        comparisons = []
        if k:
            diff = s[f"rsrp_{k}"] - s["rsrp_0"]
            comparisons.append(
                xairl.facts.Comparison(
                    f"{_WHO[k]}'s RSRP was {abs(diff):.1f} dB {'above' if diff >= 0 else 'below'} "
                    "the serving BS's RSRP",
                    round(abs(diff), 1),
                    "dB",
                )
            )
        rows = [state] if history is None else [*np.asarray(history)[-50:], state]
        held = 0
        for row in reversed(rows):  # consecutive decisions, ending now, with the strongest neighbour A3-above
            if row[RSRP][1] > row[RSRP][0] + self.offset and row[RSRQ][1] > self.detection:
                held += 1
            else:
                break
        extras["a3_decisions"] = held
        if not held:
            extras["chm"] = "stay"
        elif history is None or held == 1:
            extras["chm"] = "start its time-to-trigger"
        else:
            extras["chm"] = "hand over to candidate 1"
        if history is not None and held:
            comparisons.append(
                xairl.facts.Comparison(
                    f"the strongest neighbour has been more than {self.offset:g} dB above the "
                    f"serving BS for {held} consecutive decisions",
                    held,
                    "consecutive",
                )
            )
            # the rule's offset is a fact the sentence above cites in dB, whichever candidate the first one compares
            comparisons.append(xairl.facts.Comparison(f"the A3 offset is {self.offset:g} dB", self.offset, "dB"))
        if history is not None and len(history):
            before = 100.0 * float(np.asarray(history)[-1][FEATURES.index("buffer_queue_size")]) / self.q_max
            extras["buffer_trend"] = "rising" if fill > before + 1 else "falling" if fill < before - 1 else "steady"
        return xairl.facts.DomainFacts(extras, tuple(comparisons))


handover_facts = HandoverFacts()
