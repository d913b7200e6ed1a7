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
#: where a counterfactual may move a signal: RSRP within TS 36.133's reporting range (sec. 9.1.4, -140..-44 dBm);
#: RSRQ down to the extended reporting range's floor (TS 36.133 sec. 9.1.7, -34 dB, as exports.PLAUSIBLE cites: the
#: simulator measures the serving cell that low and its neighbours down to the -24 dB detection limit, so -19.5, the
#: basic range's floor, left states the simulator produces outside their own bounds) and up to -3 dB (what one
#: cell's RSRQ reaches with no load; RsrqFeasible bounds it by the RSRP as well)
RSRP_RANGE = (-140.0, -44.0)
RSRQ_RANGE = (-34.0, -3.0)


def _signal(kind: str, k: int, unit: str, low: str, high: str, levels, bounds) -> FeatureInfo:
    aliases = (
        (f"{kind} of candidate {k}", f"candidate {k}'s {kind}")
        if k
        else (f"serving {kind}", f"the serving cell's {kind}", f"serving cell {kind}")
    )
    return FeatureInfo(unit, f"{_WHO[k]}'s {kind}", low, high, aliases, thresholds=levels, bounds=bounds)


def feature_info(q_max_bits: float = 2e6) -> dict[str, FeatureInfo]:
    """What each feature means to an operator; the buffer's capacity is the simulator's ``q_max_bits``. For
    counterfactuals: the position and the serving cell's id never change (immutable: the question is what the radio
    or the buffer would have had to be, where the UAV was), the signals stay within their reporting ranges and the
    buffer within [0, capacity]."""
    return {
        "x": FeatureInfo("m", "the UAV's east position", "west", "east", immutable=True),
        "y": FeatureInfo("m", "the UAV's north position", "south", "north", immutable=True),
        "z": FeatureInfo("m", "the UAV's altitude", "low altitude", "high altitude", immutable=True),
        "position": FeatureInfo("", "the UAV's position", kind="group", aliases=("position (x, y, z)",)),
        "buffer_queue_size": FeatureInfo(
            "bit",
            "the uplink buffer",
            "lightly loaded",
            "heavily loaded",
            ("the uplink buffer queue", "buffer queue"),
            capacity=q_max_bits,
            bounds=(0.0, float(q_max_bits)),
        ),
        "serving_bs": FeatureInfo(
            "", "the serving BS's id", aliases=("serving BS", "on BS", "from BS"), kind="identifier", immutable=True
        ),
        **{
            f"rsrp_{k}": _signal("RSRP", k, "dBm", "weak signal", "strong signal", RSRP_LEVELS, RSRP_RANGE)
            for k in range(4)
        },
        **{
            f"rsrq_{k}": _signal("RSRQ", k, "dB", "poor quality", "good quality", RSRQ_LEVELS, RSRQ_RANGE)
            for k in range(4)
        },
    }


FEATURE_INFO = feature_info()


class RsrqFeasible:
    """The policy's ``feasible``: whether each candidate's RSRQ is one its RSRP, and the other cells' RSRP, allow.

    Derived from the simulator's own formula (``Simulator._measure``): RSRQ_k = P_k / (12 RSSI_k) with RSSI_k per
    resource element over cell k's reference-signal symbols = P_k a_k + sum_j P_j b_j + N, where P is the RSRP in mW,
    a_k = 1/3 + 2/3 load_k >= 1/3 (cell k's own reference signals, 4 of 12 elements, and its data at its load), b_j >=
    16/168 (every other cell's reference-signal share of a subframe, at load 0) and N the UE's noise per element
    (-174 dBm/Hz + 10 log10(15 kHz) + its noise figure). Every RSSI is therefore at least
    P_k/3 + (16/168) sum_{j != k} P_j + N over the measured candidates, and

        RSRQ_k <= -10 log10(12 (1/3 + (16/168) sum_{j != k} P_j / P_k + N / P_k))

    (-6.0 dB for a lone, strong cell). A state is feasible when every measured candidate's RSRQ is at most that plus
    ``tolerance_db`` (the reported values carry the UE's measurement errors after the layer-3 filter: with the
    default errors, 1.5 dB RSRQ and 1.2 dB RSRP, filtered at k=4, about 1 dB together; 3 dB is three of them) and an
    empty candidate slot (RSRQ at or below the detection limit) is anything; the serving cell is always measured. Simulated states keep at least 0.9 dB below it.
    """

    def __init__(self, noise_figure_db: float = 9.0, detection_rsrq_db: float = -24.0, tolerance_db: float = 3.0):
        self.noise_mw = 10 ** ((-174 + 10 * np.log10(15e3) + noise_figure_db) / 10)
        self.detection, self.tolerance = detection_rsrq_db, tolerance_db

    def ceiling(self, rsrp: np.ndarray, measured: np.ndarray) -> np.ndarray:
        """(n, 4) the highest RSRQ (dB) each candidate's RSRP allows beside the other measured candidates'."""
        p = 10 ** (np.asarray(rsrp, dtype=np.float64) / 10)
        others = np.where(measured, p, 0.0).sum(axis=1, keepdims=True) - np.where(measured, p, 0.0)
        return -10 * np.log10(12 * (1 / 3 + (16 / 168) * others / p + self.noise_mw / p))

    def __call__(self, states) -> np.ndarray:
        x = np.asarray(states, dtype=np.float64)
        rows = x.reshape(len(x), -1, len(SIGNALS))[..., : len(FEATURES)] if x.shape[1] != len(FEATURES) else x[:, None]
        rsrp, rsrq = rows[..., RSRP].reshape(-1, N_CANDIDATES), rows[..., RSRQ].reshape(-1, N_CANDIDATES)
        measured = rsrq > self.detection
        measured[:, 0] = True  # the serving cell is measured whatever its RSRQ (no 'empty slot' to hide it in)
        ok = ~measured | (rsrq <= self.ceiling(rsrp, measured) + self.tolerance)
        return ok.all(axis=1).reshape(len(x), -1).all(axis=1)


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
