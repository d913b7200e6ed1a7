"""Every reading of the verifier as named data: its id (what ``Claim.rule`` and ``xairl verify --trace`` show), the
kind of claim it makes, what it reads, and sentences it must fire on and must not fire on, each against one of two
small explanations defined here (:func:`example`). ``tests/test_verify_rules.py`` generates one test per example,
and fails when the code names a rule that is not here (or this table one that the code no longer makes).

How to add a rule: docs/verifier.md ("Adding a rule").
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from xairl.explanations.explanation import Explanation


@dataclass(frozen=True)
class Rule:
    """One reading: ``fires`` are (explanation, sentence) pairs whose verification holds a claim made by this rule,
    ``silent`` pairs whose verification holds none (a near miss: the phrasing another rule, or none, reads)."""

    id: str
    claims: str  # the kind of claim it makes: feature, number, direction, rank, action, category
    reads: str  # what it reads, in words
    fires: tuple[tuple[str, str], ...]
    silent: tuple[tuple[str, str], ...] = ()


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


RULES: tuple[Rule, ...] = (
    Rule(
        "names.mention",
        "feature",
        "a feature named, in any spelling or by its description's words (no claim by itself)",
        fires=(("air", "Traffic mattered."),),
        silent=(("air", "The weather mattered."),),
    ),
    Rule(
        "names.shorthand",
        "feature",
        "a compact log's shorthand of a name, right before a number: the first letters "
        "of a word ('alc' of alcohol), the word without vowels ('wknd'), a two-word name's capital initials ('VA')",
        fires=(("air", "traf 2.4: +7.2; wnd 0.8: +6.9"), ("air", "TI 2.4 (+7.2)")),
        silent=(("air", "The traf was bad."), ("air", "traffic_index 2.4 (+7.2)")),
    ),
    Rule(
        "action.choice",
        "action",
        "a statement of the chosen action or the runner-up",
        fires=(("robot", "The agent chose to turn."),),
        silent=(("robot", "Speed mattered."),),
    ),
    Rule(
        "category.label",
        "category",
        "a categorical value named: it must be the state's",
        fires=(("air", "It is winter."),),
        silent=(("air", "It is cold."),),
    ),
    Rule(
        "category.closed-class",
        "category",
        "a month, weekday, season, compass point or time of day in a sentence "
        "that names a categorical feature whose label is another of its class",
        fires=(
            ("fire", "Because it was June, the month term added +1.9."),
            ("fire", "The north-facing aspect added a little."),
        ),
        silent=(
            ("fire", "The August month term added +1.9."),
            ("fire", "The south-facing aspect added a little."),
            ("fire", "Fifteen dry days since June added 2.2."),
        ),
    ),
    Rule(
        "category.negated",
        "category",
        "a label said the other way: 'no F' when F is 'yes'; the label's word "
        "without a negation when the label is 'Not X', or with one when it is 'X'",
        fires=(
            ("fire", "With no campfire ban, the risk rose."),
            ("fire", "The tower was staffed, so patrol_status added 0.3."),
        ),
        silent=(
            ("fire", "The campfire ban lowered it by 0.4."),
            ("fire", "The tower was not staffed: patrol_status added 0.3."),
        ),
    ),
    Rule(
        "category.stated",
        "category",
        "a value given to a categorical feature right after its name ('is rated "
        "medium', \"was flagged as 'late'\", 'F=flat', a quoted value) or capitalised right before it ('the Midwifery "
        "course'): it must share a word with the state's label (or be its initials); yes/no labels are left to the "
        "direction words",
        fires=(
            ("air", "The season was listed as autumn."),
            ("air", "The road was recorded as 'four lanes'."),
            ("air", "It was the Coastal road that mattered."),
            ("air", "season=autumn traffic=+7.2"),
        ),
        silent=(
            ("air", "The season is cold."),
            ("air", "The season is 'summer'."),
            ("air", "A cold season: three signals point up."),
        ),
    ),
    Rule(
        "number.respectively",
        "number",
        "'A and B ... by x and y, respectively': the numbers pair with the names",
        fires=(("air", "Traffic and wind add 7.2 and 6.9, respectively."),),
        silent=(("air", "Traffic adds 7.2."),),
    ),
    Rule(
        "number.sum",
        "number",
        "'A and B together add x': the sum of their contributions (and a percentage "
        "after it, 'about 47 % of it': the sum of their shares of all |contributions|, of their side or of the net "
        "change)",
        fires=(
            ("air", "Traffic and wind together add 14.1."),
            ("air", "Wind and traffic together add 14.1, about 47% of it."),
            ("air", "Traffic and wind push it up, and they add 14.1."),
        ),
        silent=(("air", "Traffic and wind add 7.2 and 6.9, respectively."),),
    ),
    Rule(
        "number.too-many",
        "number",
        "the numbers of a clause after its 40th (a table or hostile text, not prose), unchecked: reading every one "
        "would grow with the numbers times the clause's length",
        fires=(("air", "Traffic raised it by " + "1, " * 45 + "in all."),),
        silent=(("air", "Traffic raised it by 1.0, wind by 2.0 and the hour by 3.0."),),
    ),
    Rule(
        "number.sum-unnamed",
        "number",
        "a number after a sum's cue word in a clause that joins one known name with "
        "words the vocabulary lacks ('the mileage and garage offsets together claw back $294'), contradicted as the "
        "name's own, or a sum whose count of things ('the three factors') is not the count of names found: a sum "
        "over things not all known, unchecked",
        fires=(
            ("air", "Traffic plus the junction make up 9.9."),
            ("air", "The three weather terms (traffic, wind and the humidity) together add 20.0."),
        ),
        silent=(
            ("air", "Traffic and wind together add 14.1."),
            ("air", "The two weather terms (traffic and wind) together add 14.1."),
        ),
    ),
    Rule(
        "number.other-side",
        "number",
        "a sum after words naming one side ('the positives add up to', 'downward "
        "ones about') that is the other side's sum in size: a sign error, contradicted",
        fires=(("air", "The negatives add up to 31.1."), ("air", "Upward contributions total about +1.0.")),
        silent=(("air", "The positives add up to 31.1."), ("air", "The negatives add up to 12.0.")),
    ),
    Rule(
        "number.aggregate",
        "number",
        "a sum over all features after its cue words ('the positives add up to')",
        fires=(("air", "The positives add up to 31.1."),),
        silent=(("air", "Traffic adds 7.2."),),
    ),
    Rule(
        "number.value-sign",
        "number",
        "a feature's value written without its sign when it is negative (beyond rounding of zero) and no word says "
        "so ('wind_gust (1.46)' when it is -1.463): a wrong value, contradicted; not with words that carry the sign "
        "('1.46 below zero', 'a drop of 1.46', 'minus 1.46', '1.46 lower than usual') nor for a contribution said "
        "after a direction word ('lowered it by 0.3')",
        fires=(
            ("gust", "wind_gust (1.46) pushed toward turn_left by +0.10."),
            ("gust", "The wind gust was 1.46."),
            ("gust", "The wind gust stood at about 1.5, which pushed toward turn_left."),
            ("gust", "wind_gust=1.463"),
        ),
        silent=(
            ("gust", "wind_gust (-1.46) pushed toward turn_left by +0.10."),
            ("gust", "The wind gust was 1.46 below zero."),
            ("gust", "The wind gust reading of minus 1.46 pushed toward turn_left."),
            ("gust", "The wind gust was negative 1.46."),
            ("gust", "The wind gust sat 1.46 standard deviations below the mean."),
            ("gust", "The wind gust, 1.46 lower than usual, pushed toward turn_left."),
            ("gust", "The wind gust showed a drop of 1.46."),
            ("gust", "The wind gust was under 2."),
            ("gust", "Altitude lowered turn_left's score by 0.3."),
            ("gust", "The wind gust was 1.46 in size and negative."),
        ),
    ),
    Rule(
        "number.identifier-after-word",
        "number",
        "a bare whole number right after one word of a longer name, "
        "after a preposition ('queued at charger 3'), contradicted as that name's: an identifier, unchecked",
        fires=(("air", "The monitor at traffic 9 was busy."),),
        silent=(("air", "Traffic adds 7.2."), ("air", "The monitor at traffic 9 km away was busy.")),
    ),
    Rule(
        "number.unit-owner",
        "number",
        "a number first read by position as another name's and contradicted, "
        "followed by a unit only one feature has ('0.6 km' of next_drop_dist_km): verified when it is that "
        "feature's value",
        fires=(("drone", "Battery at 46 and 0.6 km to go: continuing wins."),),
        silent=(("drone", "Battery at 46 and 0.9 km to go: continuing wins."),),
    ),
    Rule(
        "number.counted-in",
        "number",
        "a number first read by position as another name's and contradicted, that "
        "counts things in a name after it ('three drones in the charger queue'): verified when it is that name's "
        "value",
        fires=(("drone", "There are already three drones in the charger queue."),),
        silent=(("drone", "There are already five drones in the charger queue."),),
    ),
    Rule(
        "number.without",
        "number",
        "a number in a clause that takes named features' pushes away ('without "
        "traffic's contribution', 'remove the traffic term and', 'ignoring A and B', 'if A had contributed nothing', "
        "'had A been removed'): verified when it is the "
        "prediction, its change from the baseline or the margin less those pushes, else its other readings decide",
        fires=(
            ("air", "Without traffic's contribution, the forecast would be about 44.9."),
            ("air", "Even without the traffic term it would sit 22.9 above the average."),
            ("air", "Remove the traffic and wind terms and the forecast would sit at about 38."),
            ("air", "If traffic had contributed nothing, the forecast would be about 44.9."),
            ("air", "Had the traffic term been removed (its +7.2), the forecast would sit near 44.9."),
        ),
        silent=(("air", "Traffic adds 7.2."), ("air", "Without traffic's contribution, the forecast would be 38.")),
    ),
    Rule(
        "number.output-name",
        "number",
        "a number of a one-output model's name, written with a word it has "
        "there ('sending unit 7' of \"Q-value of the action 'send unit 7'\"): no fact, unchecked",
        fires=(("drone", "Flying on to drop 2 scores 4.56."),),
        silent=(("drone", "Continuing scores 4.56 with 3 drones queued."),),
    ),
    Rule(
        "number.change",
        "number",
        "the change from the baseline ('30.0 above the average')",
        fires=(("air", "The forecast is 30.1 above the average."),),
        silent=(("air", "Traffic adds 7.2."),),
    ),
    Rule(
        "number.cue",
        "number",
        "a number its cue words bind: the prediction, the baseline, a typical value, the margin",
        fires=(("air", "pred=52.1 base=22.0"),),
        silent=(("air", "Traffic adds 7.2."),),
    ),
    Rule(
        "number.action-scores",
        "number",
        "'turn beat recharge 3.2 to 2.0': one number per action",
        fires=(("robot", "Turn beat recharge 3.2 to 2.0."),),
        silent=(("robot", "Turn scored 3.2."),),
    ),
    Rule(
        "number.for-action",
        "number",
        "a number right before 'for' or 'by' and an action: that action's score",
        fires=(("robot", "The agent scored 3.2 for turn."),),
        silent=(("robot", "Turn scored 3.2."),),
    ),
    Rule(
        "number.push-for",
        "number",
        "'+x for the action' after a feature: its push for one option over the other",
        fires=(("robot", "Obstacle gave +2.0 for turn."),),
        silent=(("robot", "Obstacle adds 2.0."),),
    ),
    Rule(
        "number.action-before",
        "number",
        "an action, then its score ('turn scored 3.2')",
        fires=(("robot", "Turn scored 3.2."),),
        silent=(("robot", "Obstacle adds 2.0."),),
    ),
    Rule(
        "number.gives-runner-up",
        "number",
        "'speed gives recharge -0.7' when turn was chosen: the margin, flipped",
        fires=(("robot", "Speed gives recharge -0.7."),),
        silent=(("robot", "Speed gives turn +0.5."),),
    ),
    Rule(
        "number.output-after",
        "number",
        "a number right before the output's own name ('52 in pm2_5')",
        fires=(("air", "Traffic leaves 52.1 in the forecast."),),
        silent=(("air", "Traffic adds 7.2."),),
    ),
    Rule(
        "number.from-name",
        "number",
        "a push and where it comes from: 'about 14 from the 12% price increase', "
        "'19 points of that come from the contract'",
        fires=(("air", "About 7.2 of that comes from the traffic, and 6.9 from the wind."),),
        silent=(("air", "Traffic adds 7.2."),),
    ),
    Rule(
        "number.name-after",
        "number",
        "a number bound by position: the name right after it ('a 48.2 lag-1 "
        "reading'), unless it is signed or a field's value: then it ends the item before ('wait_max -2.31 elapsed')",
        fires=(("air", "A 2.4 traffic index adds to it."),),
        silent=(("air", "Traffic adds 7.2."), ("air", "pm2_5_lag1 +14.7 traffic_index +7.2")),
    ),
    Rule(
        "number.name-before",
        "number",
        "a number bound by position: the name before it in its clause",
        fires=(("air", "Traffic adds 7.2."),),
        silent=(("air", "The forecast is 52 µg/m³."),),
    ),
    Rule(
        "number.free",
        "number",
        "a number tied to no name: a decision-level fact or nothing",
        fires=(("air", "In all, 52.1."),),
        silent=(("air", "Traffic adds 7.2."),),
    ),
    Rule(
        "number.elsewhere",
        "number",
        "a number bound by position that states another fact of its sentence "
        "exactly (a decision-level number, a named feature's fact): a guess, unchecked",
        fires=(("air", "Traffic is heavy, so the forecast is 52.1."),),
        silent=(("air", "Traffic is heavy, so the forecast is 35.5."),),
    ),
    Rule(
        "number.other-feature",
        "number",
        "a number bound by position alone, contradicted, that measures no fact "
        "noun and states exactly (unhedged, two significant digits) a fact of a feature its sentence does not name: "
        "the text may name that feature in words the vocabulary lacks, or name it by one word of a long name ('bill "
        "$109.9' of price_increase_last_bill_pct when $109.9 is the monthly charge), unchecked",
        fires=(("air", "Traffic is heavy, with yesterday's level at 14.7."),),
        silent=(
            ("air", "Traffic is heavy, with yesterday's level at 12.3."),
            ("air", "Traffic is heavy, with an increase of 14.7."),
        ),
    ),
    Rule(
        "number.unclear",
        "number",
        "a number bound by position that states another named feature's fact exactly "
        "(unhedged, two significant digits): which one is unclear, unchecked",
        fires=(("air", "The wind was calm, which, with the traffic, added 6.9."),),
        silent=(("air", "The wind was calm, which, with the traffic, added 5.5."),),
    ),
    Rule(
        "number.crossed",
        "number",
        "a number bound by position that states another feature's fact, while a "
        "number bound to that other feature states this one's, anywhere in the text: the two are swapped, "
        "contradicted",
        fires=(
            ("air", "Traffic adds 6.9 and wind adds 7.2."),
            ("air", "traffic_index=2.4 (+6.9) wind_speed_ms=0.8 (+7.2)"),
            ("air", "- traffic 2.4 -> +6.9\n- wind 0.8 -> +7.2"),
        ),
        silent=(("air", "Traffic adds 7.2 and wind adds 6.9."), ("air", "Traffic adds 6.9, more than the wind.")),
    ),
    Rule(
        "number.side-share",
        "number",
        "a percentage of one side ('46% of all upward contributions'): the share of "
        "its side of a feature the sentence names there; contradicted when it names one such feature only",
        fires=(("air", "The traffic is also about 47% of the upward push."),),
        silent=(("air", "Traffic adds 7.2."), ("air", "Traffic is about 23% of the upward push.")),
    ),
    Rule(
        "number.word",
        "number",
        "a number word bound by position alone, that the parse ties to no name ('a "
        "factor of two', 'one and a half times'): a count or an idiom, unchecked",
        fires=(("air", "The wind mattered by a factor of two."),),
        silent=(("air", "Traffic adds seven."),),
    ),
    Rule(
        "number.log-field",
        "number",
        "an unsigned value of a log's field that names nothing ('run_id=7781')",
        fires=(("air", "pm2_5_lag1=+14.7 run_id=7781"),),
        silent=(("air", "pm2_5_lag1=+14.7 humidity_pct=+3.1"),),
    ),
    Rule(
        "number.of-identifier",
        "number",
        "a number right after an identifier that names nothing, with or without "
        "the identifier's own value ('wait_max -2.31', 'blh_m=310|+4.6'): the identifier's, not the name's before "
        "it; unchecked (the identifier's own claim judges it)",
        fires=(("air", "pm2_5_lag1 +14.7 wind_gust -3.1"), ("air", "pm2_5_lag1=48.2|+14.7 blh_m=310|+4.6")),
        silent=(("air", "pm2_5_lag1 +14.7 wind_speed_ms +6.9"), ("air", "pm2_5_lag1=+14.7 run_id=7781")),
    ),
    Rule(
        "parse.measures-name",
        "number",
        "the parse: a number measures another name than its position says",
        fires=(("air", "The precip, which unlike the traffic was nil, added about 2.2."),),
        silent=(("air", "Traffic adds 7.2."),),
    ),
    Rule(
        "parse.counts-other",
        "number",
        "the parse: a number counts a noun the explanation holds no fact of ('30 days'): unchecked",
        fires=(("air", "Traffic over the last 30 days adds 7.2."),),
        silent=(("air", "Traffic adds 7.2."),),
    ),
    Rule(
        "parse.measures-whole",
        "number",
        "the parse: a number measures a whole ('the net change of 30.0')",
        fires=(("air", "Traffic matters: of the 30.1 net change, it gives 7.2."),),
        silent=(("air", "Traffic adds 7.2."),),
    ),
    Rule(
        "parse.label-number",
        "category",
        "the parse: a number inside a categorical label ('a two-year contract')",
        fires=(("air", "The road has four lanes."),),
        silent=(("air", "The road matters little."),),
    ),
    Rule(
        "parse.said-of-other",
        "number",
        "the parse: a number said of a subject noun that names nothing, stating "
        "another feature's exact fact: unchecked",
        fires=(("air", "Heavy traffic adds about 7.2, and yesterday's high reading adds 14.7."),),
        silent=(("air", "Heavy traffic adds about 7.2, and yesterday's high reading adds 11.3."),),
    ),
    Rule(
        "parse.other-clause",
        "number",
        "the parse: a number bound by position to a name in another clause, "
        "whose own subject is something else ('Traffic is heavy, so the count of buses reaches 3.0'): unchecked",
        fires=(("air", "Traffic is heavy, so the count of buses reaches 3.0."),),
        silent=(("air", "Traffic is heavy and adds 3.0."),),
    ),
    Rule(
        "parse.direction-other-clause",
        "direction",
        "the parse: a direction word whose clause has a subject of "
        "its own, and the name first read as its subject sits in another clause ('Heavy traffic means the buses "
        "run late, so the model lowers it'): unchecked",
        fires=(("air", "Heavy traffic means the buses run late, so the model lowers it by 3.0."),),
        silent=(("air", "Traffic lowers the forecast by 3.0."),),
    ),
    Rule(
        "parse.modifier",
        "rank",
        "the parse: a rank (or a number stating some feature's exact fact) bound to a "
        "name that only qualifies a noun naming nothing ('the wind queue'): about that noun, unchecked",
        fires=(("air", "The main reason is the wind queue at the junction."),),
        silent=(("air", "The main reason is the wind."),),
    ),
    Rule(
        "direction.subject",
        "direction",
        "a direction word and the names it is said of",
        fires=(("air", "Traffic raised the forecast."),),
        silent=(("air", "Traffic mattered."),),
    ),
    Rule(
        "direction.unknown-name",
        "direction",
        "a signed number after a label that names no feature",
        fires=(("air", "humidity +3.1; traffic +7.2"),),
        silent=(("air", "traffic +7.2"),),
    ),
    Rule(
        "direction.by-number",
        "direction",
        "a direction word of a clause that names no feature, with a number "
        "after it (before the next one) that is one feature's contribution in size and no decision-level number: "
        "that feature's push",
        fires=(
            ("air", "Something else was at work; it raised the forecast by 14.7."),
            ("air", "Something raised it by 14.7 and something else lowered it by 1.0."),
        ),
        silent=(
            ("air", "Something else was at work; it raised the forecast by 30.1."),
            ("air", "Something else was at work; it costs about 14.7."),
        ),
    ),
    Rule(
        "direction.without",
        "direction",
        "'without X it would be lower': what X did, by taking it away",
        fires=(("air", "Without the traffic, the forecast would be lower."),),
        silent=(("air", "With the traffic, the forecast is higher."),),
    ),
    Rule(
        "rank.words",
        "rank",
        "'the biggest', 'second', 'the main reason' of a name ('A and B dominate': the top "
        "two; 'the main thing holding the number down': among the contributions of that sign)",
        fires=(
            ("air", "Traffic is the second biggest factor."),
            ("air", "The season is the main thing holding the forecast down."),
            ("air", "After pm2_5_lag1, the biggest single factor is traffic."),
        ),
        silent=(("air", "Traffic adds 7.2."), ("air", "The wind adds 6.9, about half the next-biggest effect.")),
    ),
    Rule(
        "rank.comparison",
        "rank",
        "'A mattered more than B', ratios ('twice as much as', 'about 3 times the B effect', '32 % of the B effect')",
        fires=(
            ("air", "Traffic mattered more than wind."),
            ("air", "The precip effect is roughly 32% of the wind effect."),
            ("air", "Traffic had a bigger effect than the number of wind gusts did."),
            ("air", "Traffic weighs more in this forecast than the city's morning wind."),
            ("air", "Traffic is larger than the season (-1.0) by a factor of ~7."),
        ),
        silent=(
            ("air", "Traffic adds 7.2."),
            ("air", "The precip effect is roughly 32% of the change."),
            ("air", "Traffic mattered more than any other wind."),
            ("air", "The positives more than cancel the season's -1.0."),
        ),
    ),
    Rule(
        "rank.minor",
        "rank",
        "'barely mattered' of a name",
        fires=(("air", "The season barely mattered."),),
        silent=(("air", "The season mattered."),),
    ),
    Rule(
        "identifier.claimed",
        "feature",
        "an identifier that is no name, given a number or a direction word: an invented feature",
        fires=(("air", "humidity_pct=+3.1"),),
        silent=(("air", "run_id=7781"),),
    ),
    Rule(
        "identifier.invented",
        "feature",
        "a feature-like identifier ('wind_speed', 'windSpeed', 'sensor[7]', 'the feature humidity') that names no "
        "feature, action, label, unit or word of a description, given a contribution, a number or a direction later "
        "in its clause: an invented feature, contradicted",
        fires=(
            ("gust", "The feature wind_speed contributed +0.50 toward this action."),
            ("gust", "The feature humidity contributed +0.50 toward turn_left."),
            ("gust", "Its windSpeed input, at the moment, pushed toward turn_left."),
            ("gust", "sensor[7] of the gimbal contributed +0.2."),
            ("robot", "The battery_temp reading, high today, lowered the score by 0.3."),
        ),
        silent=(
            ("gust", "The weather contributed +0.10 toward turn_left."),  # plain words: no identifier
            ("gust", "The wind_gust reading, at the moment, pushed toward turn_left."),  # a known name
            ("gust", "With deep_shap as the method, heading_error pushed toward turn_left by +0.60."),
            ("gust", "Run with kernel_shap and integrated_gradients, the result was the same: +0.60."),
            ("gust", "Choosing turn_left over turn_right, heading_error added +0.70."),  # actions
            ("gust", "Not wind_speed but heading_error pushed toward turn_left by +0.60."),  # negated
            ("gust", "The feature importance of heading_error is +0.60."),
            ("gust", "See run_log for details; heading_error added +0.60."),  # its claim is another name's
            ("air", "The wind_speed reading, at the time, added +6.9."),  # part of wind_speed_ms
        ),
    ),
    Rule(
        "identifier.q-of-action",
        "action",
        "'Q_x' of no action",
        fires=(("robot", "Q_jump was high."),),
        silent=(("robot", "Q_turn was high."),),
    ),
    Rule(
        "identifier.other",
        "feature",
        "any other identifier: unchecked",
        fires=(("air", "run_id=7781"),),
        silent=(("air", "Traffic adds 7.2."),),
    ),
    Rule(
        "region.unknown",
        "feature",
        "an image region's name that names no region of the explanation",
        fires=(("air", "The 8x8 patch at rows 0 to 7, columns 0 to 7 of channel 0 mattered."),),
        silent=(("air", "Traffic mattered."),),
    ),
)

BY_ID = {r.id: r for r in RULES}
