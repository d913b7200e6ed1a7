"""The DQN's state layout (as in the paper) and what each feature means, for plots and narration."""
from xairl.policy import FeatureInfo

FEATURES = ("x", "y", "z", "buffer_queue_size", "serving_bs",
            "rsrp_0", "rsrp_1", "rsrp_2", "rsrp_3", "rsrq_0", "rsrq_1", "rsrq_2", "rsrq_3")
#: action k: associate with candidate k; candidate 0 is the serving BS, so action 0 is "stay"
ACTIONS = ("stay", "handover_to_candidate_1", "handover_to_candidate_2", "handover_to_candidate_3")
GROUPS = {"position": ("x", "y", "z"), "rsrp": ("rsrp_0", "rsrp_1", "rsrp_2", "rsrp_3"),
          "rsrq": ("rsrq_0", "rsrq_1", "rsrq_2", "rsrq_3")}


def _cand(k: int) -> str:
    return "the serving BS" if k == 0 else f"candidate BS {k} (the {['', 'strongest', 'second strongest', 'third strongest'][k]} neighbour)"


FEATURE_INFO = {
    "x": FeatureInfo("m", "the UAV's east position", "west", "east"),
    "y": FeatureInfo("m", "the UAV's north position", "south", "north"),
    "z": FeatureInfo("m", "the UAV's altitude", "low altitude", "high altitude"),
    "buffer_queue_size": FeatureInfo("bit", "the uplink buffer queue", "nearly empty buffer", "nearly full buffer"),
    "serving_bs": FeatureInfo("", "the serving BS's id", "low id", "high id"),
    **{f"rsrp_{k}": FeatureInfo("dBm", f"the RSRP of {_cand(k)}", "weak signal", "strong signal") for k in range(4)},
    **{f"rsrq_{k}": FeatureInfo("dB", f"the RSRQ of {_cand(k)}", "poor quality", "good quality") for k in range(4)},
}
