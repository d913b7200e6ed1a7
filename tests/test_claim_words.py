"""The claim-word scanner (xairl/verification/claims.py): each kind of claim word a template may write only through a
tracked filter is found with the filter to use, names and identifiers are claims, and filler never is."""

import time

import pytest

from xairl.templates.tracking import Fact, Span
from xairl.verification.claims import KINDS, ClaimWord, checked_by_counterfactual, claim_words, lexicon


@pytest.mark.parametrize(
    "text, word, kind, use",
    [
        ("Speed raised the margin.", "raised", "direction", "dir('raised', 'lowered')"),
        ("It pushed towards the goal.", "towards", "direction", "dir('towards', 'against')"),
        ("The queue was high.", "high", "level", "level('low', 'typical', 'high')"),
        ("The biggest push came from speed.", "biggest", "rank", "rank('the biggest'"),
        ("It came in second.", "second", "rank", "rank('first', 'second'"),
        ("Wind mattered less than speed.", "less", "comparison", "cmp(other"),
        ("The policy did not choose it.", "not", "negation", "dir("),
        ("It is false that it turned.", "false", "negation", "claim filter"),
        ("It turned because of the speed.", "because of", "cause", "dir('because of', 'despite')"),
        ("Due to wind, it stayed.", "Due to", "cause", "dir('due to'"),
        ("Battery helped.", "helped", "cause", "dir('helped', 'hurt')"),
        ("The policy chose it.", "chose", "role", "action|role('chose')"),
        ("It preferred that.", "preferred", "role", "role('preferred')"),
        ("Recharge beat it.", "beat", "role", "role('beat')"),
        ("Hold came second.", "came second", "role", "role('came first', 'came second')"),
        ("Left rather than right.", "rather than", "role", "role('', 'rather than')"),
        ("Every feature favoured it.", "Every", "rank", "each feature's own filter"),
    ],
)
def test_each_kind_of_claim_word_is_found_with_its_filter(text, word, kind, use):
    found = [w for w in claim_words(text) if w.word == word]
    assert found, claim_words(text)
    (w,) = found
    assert w.kind == kind and use in w.use and text[w.start : w.end] == word


def test_every_kind_has_words():
    kinds = {kind for kind, _ in lexicon().words.values()}
    assert kinds == set(KINDS)


def test_multi_word_entries_win_over_their_parts_and_span_line_breaks():
    (w,) = claim_words("it stayed because\nof the wind")
    assert (w.word, w.kind) == ("because\nof", "cause")
    assert [w.word for w in claim_words("came  second")] == ["came  second"]


def test_case_curly_apostrophes_and_inflections():
    assert [w.word for w in claim_words("RAISED, Raises, raising")] == ["RAISED", "Raises", "raising"]
    assert [w.kind for w in claim_words("It didn\u2019t favour it.")] == ["negation", "direction"]


def test_whole_words_only():
    # 'high' in 'highway', 'low' in 'allowed', 'cut' in 'shortcut', 'led' in 'labelled' are no claims
    assert claim_words("the highway allowed a shortcut, labelled") == []


def test_names_labels_and_identifiers_are_claims():
    names = ["speed", "queue_len", "the outside temperature", "turn_left"]
    found = claim_words(
        "Speed and the outside  temperature, helped by cell_load and cellLoad, before turn_left.", names
    )
    assert [(w.word, w.kind) for w in found] == [
        ("Speed", "name"),
        ("the outside  temperature", "name"),
        ("helped", "cause"),
        ("cell_load", "name"),
        ("cellLoad", "name"),
        ("turn_left", "name"),
    ]
    assert "{{ f.label }}" in found[0].use
    assert "invented one" in found[3].use  # not a name of the policy


def test_a_label_holding_a_claim_word_is_one_name():
    (w,) = claim_words("the strongest neighbour's RSRP was weak", ["the strongest neighbour's RSRP"])[:1]
    assert (w.word, w.kind) == ("the strongest neighbour's RSRP", "name")


@pytest.mark.parametrize(
    "text",
    [
        "The score of the policy over the margin was 0.3 by 2, with 4 for the feature to 5.",
        "The margin of 1.2 over the runner's score, 12.5 % of the total, on average over the background.",
        "-85.3 dBm, 3 kHz, 12 mWh, 4.2 m/s, 17 dB, a Q-value of 2, E[Q] = 3.",
        "While on BS 15, the UAV's uplink buffer was 12 % full at the time-to-trigger.",
    ],
)
def test_filler_is_never_a_claim(text):
    assert claim_words(text, ["value", "score"]) == []  # (a name that is filler is left out too)


def test_offsets_hold_where_tracked_spans_are_blanked():
    text = "        raised the margin"  # a tracked name blanked with spaces
    (w,) = claim_words(text)
    assert (w.start, w.end) == (8, 14) and isinstance(w, ClaimWord)


def test_a_sentence_printing_counterfactual_facts_is_checked_by_that_check():
    cf = Span(0, 4, "turn", Fact("cf_action"))
    plain = Span(0, 4, "turn", Fact("action", role="chosen"))
    assert checked_by_counterfactual([plain, cf]) and not checked_by_counterfactual([plain])


def test_it_is_fast():
    text = (
        "The policy chose turn_left over hold by 0.32 because the speed (4.2 m/s) raised the margin most, while "
        "the temperature lowered it and the queue was high."
    )
    names = ["speed", "temperature", "queue_len", "turn_left", "hold"]
    claim_words(text, names)
    t0 = time.perf_counter()
    for _ in range(200):
        claim_words(text, names)
    assert (time.perf_counter() - t0) / 200 < 2e-3  # (measured ~0.1 ms; a loaded machine gets room)
