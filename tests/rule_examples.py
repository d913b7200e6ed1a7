"""The explanations the rule table's examples (xairl/verification/prose/rules.yaml) and the provenance tests are read
against."""

from __future__ import annotations

import functools

import numpy as np

from xairl.explanations.explanation import Explanation


@functools.cache
def example(name: str) -> Explanation:
    """The two explanations the examples are read against.

    ``air``: next-day PM2.5 in µg/m³ (one output): base 22.0, prediction 52.1; precip_mm_24h 0 (+2.2),
    wind_speed_ms 0.8 (+6.9), pm2_5_lag1 48.2 (+14.7), traffic_index 2.4 (+7.2), season winter (-1.0), road
    '4 lanes' (+0.1).

    ``drone``: the Q-value of continuing to drop 2 (one output), base 3.1; next_drop_dist_km 0.6 (+1.15),
    charger_queue_len 3 (-0.27), battery_pct 46 (+0.49), drone_model X2 (+0.09); no policy, so units come from the
    names.

    ``fire``: ignition risk (one output), base 4.0; month August (+1.9), aspect south-west (+0.6), days_since_rain
    15 (+2.2), campfire_ban yes (-0.4), patrol_status 'Not Staffed' (+0.3); only the state's labels are known.

    ``robot``: a discrete policy; turn (3.2) chosen over recharge (2.0) and forward (-0.5), base 1.0 each; on the
    chosen score speed +0.5, battery -0.3, obstacle +2.0; on the margin over recharge speed +0.7, battery -1.5,
    obstacle +2.0.

    ``gust``: a discrete policy with a negative value; turn_left (0.4) chosen over turn_right (0.05), base 0 each;
    wind_gust -1.463 (+0.10 on turn_left's score, +0.15 on the margin), altitude 0.8 (-0.30, -0.50), heading_error
    2.5 (+0.60, +0.70).
    """
    if name == "gust":
        c = np.array([[0.10, -0.05], [-0.30, 0.2], [0.6, -0.1]])
        return Explanation(
            values=c[None],
            base_values=np.zeros((1, 2)),
            outputs=c.sum(axis=0)[None],
            states=np.array([[-1.463, 0.8, 2.5]]),
            feature_names=("wind_gust", "altitude", "heading_error"),
            action_names=("turn_left", "turn_right"),
            method="given",
        )
    if name == "air":
        c = np.array([2.2, 6.9, 14.7, 7.2, -1.0, 0.1])
        return Explanation(
            values=c.reshape(1, -1, 1),
            base_values=np.array([[22.0]]),
            outputs=np.array([[22.0 + c.sum()]]),
            states=np.array([[0.0, 0.8, 48.2, 2.4, 0.0, 1.0]]),
            feature_names=("precip_mm_24h", "wind_speed_ms", "pm2_5_lag1", "traffic_index", "season", "road"),
            action_names=("forecast",),
            method="given",
            output="value",
            categories={"season": ("winter", "summer"), "road": ("2 lanes", "4 lanes")},
        )
    if name == "drone":
        c = np.array([1.15, -0.27, 0.49, 0.09])
        return Explanation(
            values=c.reshape(1, -1, 1),
            base_values=np.array([[3.1]]),
            outputs=np.array([[3.1 + c.sum()]]),
            states=np.array([[0.6, 3.0, 46.0, 0.0]]),
            feature_names=("next_drop_dist_km", "charger_queue_len", "battery_pct", "drone_model"),
            action_names=("continue to drop 2",),
            method="given",
            output="value",
            categories={"drone_model": ("X2", "X3")},
        )
    if name == "fire":
        c = np.array([1.9, 0.6, 2.2, -0.4, 0.3])
        return Explanation(
            values=c.reshape(1, -1, 1),
            base_values=np.array([[4.0]]),
            outputs=np.array([[4.0 + c.sum()]]),
            states=np.array([[0.0, 0.0, 15.0, 0.0, 0.0]]),
            feature_names=("month", "aspect", "days_since_rain", "campfire_ban", "patrol_status"),
            action_names=("ignition risk",),
            method="given",
            output="value",
            categories={
                "month": ("August",),
                "aspect": ("south-west",),
                "campfire_ban": ("yes",),
                "patrol_status": ("Not Staffed",),
            },
        )
    c = np.array([[0.5, -0.2, 0.1], [-0.3, 1.2, -0.1], [2.0, 0.0, -1.5]])
    return Explanation(
        values=c[None],
        base_values=np.ones((1, 3)),
        outputs=(1 + c.sum(axis=0))[None],
        states=np.array([[0.4, 0.3, 0.9]]),
        feature_names=("speed", "battery", "obstacle"),
        action_names=("turn", "recharge", "forward"),
        method="given",
    )
