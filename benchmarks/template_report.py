"""The summaries and the printed report of benchmarks/bench_templates.py: per set and template, the built-ins, the
mutation corpora, with example misses."""

from __future__ import annotations

from collections import defaultdict

from benchmarks.template_mutations import _operator

CATEGORIES = ("numbers", "directions", "swaps", "invented", "actions", "signs")
MAX_EXAMPLES = 5


def decisions_of(spec: dict, n: int):
    """The decisions a template renders on: index None for a global template, else the first ``n``."""
    return [None] if spec.get("kind") == "global" else list(range(n))


def _bad_claims(res) -> list:
    return [c for c in res.get("claims", []) if c[2] == "contradicted"]


def _example(tname, kind, index, res, extra=None) -> dict:
    ex = {
        "template": tname,
        "kind": kind,
        "decision": index,
        "text": res.get("text"),
        "sentences": [s for s in res.get("sentences", []) if s[1] != "verified"],
        "contradicted": _bad_claims(res),
    }
    if extra:
        ex.update(extra)
    return ex


def summarise_set(set_name, templates, results, twins, n, kinds):
    """Per template and kind: verified/rendered (correct), caught/wrong (wrong), n/a; the twins' own verification."""
    rows, misses, false_rejections, twin_rows = [], [], [], []
    for t in templates:
        for kind in kinds:
            if kind not in t["kinds"]:
                continue
            row = {"template": t["name"], "kind": kind, "correct": t["correct"], "rendered": 0, "na": 0, "errors": 0}
            row.update(
                {"verified": 0, "contradicted": 0}
                if t["correct"]
                else {"wrong": 0, "caught": 0, "same_as_twin": 0, "verified": 0}
            )
            trow = {"template": t["name"], "kind": kind, "rendered": 0, "verified": 0, "na": 0}
            for i in decisions_of(t["spec"], n):
                res = results[((set_name, t["name"]), kind, i)]
                if "na" in res or "error" in res:
                    row["na" if "na" in res else "errors"] += 1
                    row.setdefault("message", res.get("na") or res.get("error"))
                    continue
                row["rendered"] += 1
                if t["correct"]:
                    row["verified"] += res["verified"]
                    row["contradicted"] += bool(_bad_claims(res))
                    if not res["verified"]:
                        false_rejections.append(_example(t["name"], kind, i, res))
                    continue
                twin = twins[((set_name + "-twin", t["name"]), kind, i)]
                if "text" in twin:
                    trow["rendered"] += 1
                    trow["verified"] += twin["verified"]
                    if not twin["verified"]:
                        false_rejections.append(_example(t["name"] + " (twin)", kind, i, twin))
                else:
                    trow["na"] += 1
                if "text" not in twin or twin["text"] == res["text"]:
                    row["same_as_twin"] += 1
                    continue
                row["wrong"] += 1
                row["caught"] += not res["verified"]
                row["verified"] += res["verified"]
                if res["verified"]:
                    misses.append(_example(t["name"], kind, i, res, {"twin_text": twin["text"]}))
            rows.append(row)
            if not t["correct"]:
                twin_rows.append(trow)
    summary = _set_summary(rows, twin_rows, templates)
    return {
        "rows": rows,
        "twins": twin_rows,
        "summary": summary,
        "false_rejections": false_rejections,
        "misses": misses,
    }


def _set_summary(rows: list[dict], twin_rows: list[dict], templates: list[dict]) -> dict:
    """A set's totals: issue 65's figures (correct renderings contradicted, wrong ones verified, correct templates
    neither verified nor flagged by prompts check), then verified, caught and the twins'."""
    correct = [r for r in rows if r["correct"]]
    wrong = [r for r in rows if not r["correct"]]
    flagged = {t["name"] for t in templates if t.get("flagged")}
    failing = sorted({r["template"] for r in correct if r["verified"] < r["rendered"]})
    return {
        "correct_contradicted": sum(r["contradicted"] for r in correct),
        "wrong_verified": sum(r["verified"] for r in wrong),
        # issue 65: every correct template verifies every rendering, or `xairl prompts check` flags it
        "correct_neither_verified_nor_flagged": [t for t in failing if t not in flagged],
        "flagged_by_prompts_check": {t["name"]: t["flagged"] for t in templates if t.get("flagged")},
        "correct_verified": sum(r["verified"] for r in correct),
        "correct_rendered": sum(r["rendered"] for r in correct),
        "wrong_caught": sum(r["caught"] for r in wrong),
        "wrong_renderings": sum(r["wrong"] for r in wrong),
        "twins_verified": sum(r["verified"] for r in twin_rows),
        "twins_rendered": sum(r["rendered"] for r in twin_rows),
        "not_applicable": sum(r["na"] for r in rows),
        "errors": sum(r["errors"] for r in rows),
        "failing_correct_templates": failing,
        "templates_with_missed_wrong": sorted({r["template"] for r in wrong if r["caught"] < r["wrong"]}),
        "twins_not_verified": sorted({r["template"] for r in twin_rows if r["verified"] < r["rendered"]}),
    }


def summarise_builtins(templates, results, n, kinds):
    rows, false_rejections = [], []
    for t in templates:
        for kind in t["kinds"]:
            row = {"template": t["name"], "kind": kind, "rendered": 0, "verified": 0, "na": 0, "errors": 0}
            for i in decisions_of(t["spec"], n):
                res = results[(("builtin", t["name"]), kind, i)]
                if "na" in res or "error" in res:
                    row["na" if "na" in res else "errors"] += 1
                    row.setdefault("message", res.get("na") or res.get("error"))
                    continue
                row["rendered"] += 1
                row["verified"] += res["verified"]
                if not res["verified"]:
                    false_rejections.append(_example(t["name"], kind, i, res))
            rows.append(row)
    return {
        "rows": rows,
        "summary": {
            "verified": sum(r["verified"] for r in rows),
            "rendered": sum(r["rendered"] for r in rows),
            "failing": sorted({r["template"] for r in rows if r["verified"] < r["rendered"]}),
        },
        "false_rejections": false_rejections,
    }


def _count_mutant(tally: dict, per_template: list, label: str, verified: bool) -> None:
    """One rendering of a mutated template: counted, and caught unless it verified (per operator, per template)."""
    tally["mutated"] += 1
    tally["caught"] += not verified
    for counts in (tally.setdefault("by_operator", {}).setdefault(_operator(label), [0, 0]), per_template):
        counts[0] += not verified
        counts[1] += 1


def summarise_mutations(meta, results, n):
    cats = {c: {"mutated": 0, "caught": 0, "templates": 0, "unchanged": 0, "na": 0} for c in CATEGORIES}
    para = {"rendered": 0, "rejected": 0, "templates": 0, "unchanged": 0, "na": 0, "original_not_verified": 0}
    misses, rejections = defaultdict(list), []
    per_template = defaultdict(lambda: defaultdict(lambda: [0, 0]))
    for key, (src, t, cat, label) in meta.items():
        tally = para if cat == "paraphrase" else cats[cat]
        tally["templates"] += 1
        for kind in t["kinds"]:
            for i in decisions_of(t["spec"], n):
                res = results[(key, kind, i)]
                orig = results[((src, t["name"]), kind, i)]
                if "text" not in res or "text" not in orig:
                    tally["na"] += 1
                    continue
                if res["text"] == orig["text"]:
                    tally["unchanged"] += 1
                    continue
                if cat == "paraphrase":
                    if not orig["verified"]:
                        tally["original_not_verified"] += 1
                        continue
                    tally["rendered"] += 1
                    if not res["verified"]:
                        tally["rejected"] += 1
                        rejections.append(_example(t["name"], kind, i, res, {"mutation": label, "source": src}))
                    continue
                if cat == "signs" and not orig.get("negative_value"):
                    tally["unchanged"] += 1
                    continue
                _count_mutant(tally, per_template[f"{src}:{t['name']}"][cat], label, res["verified"])
                if res["verified"]:
                    extra = {"mutation": label, "source": src, "original": orig["text"]}
                    misses[cat].append(
                        _example(t["name"], kind, i, res, {**extra, "claims": _changed_claims(res, orig)})
                    )
    return {
        "categories": cats,
        "paraphrases": para,
        "per_template": {k: {c: v for c, v in d.items()} for k, d in per_template.items()},
        "miss_counts": {c: len(v) for c, v in misses.items()},
        "misses": {c: _diverse(v, MAX_EXAMPLES) for c, v in misses.items()},
        "all_misses": {c: v for c, v in misses.items()},
        "paraphrase_rejections": _diverse(rejections, MAX_EXAMPLES),
        "all_paraphrase_rejections": rejections,
    }


def _changed_claims(res, orig) -> list:
    """The claims of the sentences that differ from the original rendering's (all claims when none is found)."""
    before = {s for s, _ in orig.get("sentences", [])}
    changed = [s for s, _ in res.get("sentences", []) if s not in before]
    claims = [c for c in res.get("claims", []) if any(c[1] and c[1] in s for s in changed)]
    return (claims or res.get("claims", []))[:12]


def _diverse(items, k):
    """Up to k examples: one per kind of edit first, then one per template, then the rest."""
    seen_op, seen_t, first, second, rest = set(), set(), [], [], []
    for ex in items:
        op, t = _operator(ex.get("mutation") or ""), ex["template"]
        if op not in seen_op:
            first.append(ex)
        elif t not in seen_t:
            second.append(ex)
        else:
            rest.append(ex)
        seen_op.add(op)
        seen_t.add(t)
    return (first + second + rest)[:k]


def _pct(a, b):
    return f"{a}/{b}" + (f" ({100 * a / b:.1f} %)" if b else "")


def print_report(report, tsets):
    if "timing" in report:
        _print_timing(report["timing"])
    for s, res in report["sets"].items():
        title = {"custom": "Set 1 (custom, frozen)", "heldout": "Set 2 (HELD OUT)", "builtin": "Built-in templates"}
        print(f"\n{title.get(s, s)}")
        if s == "builtin":
            _print_builtins(res)
        else:
            _print_set(s, res, tsets[s], report["kinds"])
    if s := report.get("sets", {}).get("builtin"):
        for ex in s["false_rejections"][:MAX_EXAMPLES]:
            _print_example("BUILT-IN FALSE REJECTION", ex)
    if "mutations" in report:
        _print_mutations(report["mutations"])


def _print_timing(timing):
    print("\nItem 5: verifying an own narrative with provenance, ms per sentence (goal: <= 2 ms)")
    print(f"  {'kind':<11} {'narr.':>5} {'sent.':>6} {'median':>7} {'p95':>7} | {'reader med':>10} {'p95':>7} | ratio")
    for kind, r in timing.items():
        print(
            f"  {kind:<11} {r['narratives']:>5} {r['sentences']:>6} {r['provenance_median_ms']:>7.2f} "
            f"{r['provenance_p95_ms']:>7.2f} | {r['reader_median_ms']:>10.2f} {r['reader_p95_ms']:>7.2f} | "
            f"{r['ratio_median']:.2f}  (verify(provenance).ok == narrate.verified: "
            f"{r['verify_agrees_with_narrate']}/{r['narratives']})"
        )
        if r.get("note"):
            print(f"    note ({kind}): {r['note'][:200]}; timed per dimension (Explanation.output_slice)")


def _print_builtins(res):
    for r in res["rows"]:
        na = f"  n/a {r['na']}: {r['message'][:100]}" if r["na"] else ""
        err = f"  ERRORS {r['errors']}: {r['message'][:100]}" if r["errors"] else ""
        print(f"  {r['template']:<28} {r['kind']:<11} verified {r['verified']}/{r['rendered']}{na}{err}")
    sm = res["summary"]
    print(f"  => built-ins verified {_pct(sm['verified'], sm['rendered'])}; failing: {sm['failing']}")


def _print_set(s, res, templates, kinds):
    header = "  " + f"{'template':<36}" + "".join(f"{k:>12}" for k in kinds)
    print(header + "   (correct: verified/rendered; wrong: caught/wrong)")
    by = {(r["template"], r["kind"]): r for r in res["rows"]}
    for t in templates:
        cells = []
        for k in kinds:
            r = by.get((t["name"], k))
            if r is None:
                cells.append("-")
            elif r["rendered"] == 0 and (r["na"] or r["errors"]):
                cells.append("n/a" if r["na"] else "ERR")
            elif t["correct"]:
                cells.append(f"{r['verified']}/{r['rendered']}")
            else:
                cells.append(f"{r['caught']}/{r['wrong']}")
        mark = "" if t["correct"] else " [wrong]"
        print("  " + f"{t['name'] + mark:<36}" + "".join(f"{c:>12}" for c in cells))
    for r in res["rows"]:
        if r["na"] or r["errors"]:
            print(f"    n/a {r['template']} on {r['kind']} ({r['na']} n/a, {r['errors']} errors): {r['message'][:160]}")
    tw = {(r["template"], r["kind"]): r for r in res["twins"]}
    if tw:
        print(
            "  twins (corrected copies of the wrong templates) verified: "
            + ", ".join(f"{t}/{k} {r['verified']}/{r['rendered']}" for (t, k), r in tw.items())
        )
    sm = res["summary"]
    print(
        f"  => correct renderings contradicted: {sm['correct_contradicted']}; wrong renderings verified: "
        f"{sm['wrong_verified']}; correct templates neither verified on every rendering nor flagged by prompts "
        f"check: {sm['correct_neither_verified_nor_flagged']}"
    )
    for name, lines in sm["flagged_by_prompts_check"].items():  # (a held-out set's words are not printed)
        example = "" if s == "heldout" else f", e.g. {lines[0].split('/')[-1][:150]}"
        print(f"     prompts check flags {name}: {len(lines)} line(s){example}")
    print(
        f"     correct renderings verified {_pct(sm['correct_verified'], sm['correct_rendered'])}; wrong renderings "
        f"caught {_pct(sm['wrong_caught'], sm['wrong_renderings'])}; twins verified "
        f"{_pct(sm['twins_verified'], sm['twins_rendered'])}; n/a {sm['not_applicable']}, errors {sm['errors']}"
    )
    print(
        f"     failing correct templates: {sm['failing_correct_templates']}; wrong templates with misses: "
        f"{sm['templates_with_missed_wrong']}; twins not verified: {sm['twins_not_verified']}"
    )
    if s != "heldout":  # the held-out set's texts are not printed
        for ex in res["false_rejections"][:MAX_EXAMPLES]:
            _print_example("FALSE REJECTION", ex)
        for ex in res["misses"][:MAX_EXAMPLES]:
            _print_example("MISSED WRONG", ex)


def _print_mutations(m):
    print("\nMutation corpora (set 1's correct templates and the built-ins): caught / mutated renderings")
    for c, r in m["categories"].items():
        print(
            f"  {c:<11} {_pct(r['caught'], r['mutated']):>24}   ({r['templates']} mutated templates; "
            f"{r['unchanged']} renderings unchanged, {r['na']} n/a)"
        )
    p = m["paraphrases"]
    print(
        f"  paraphrases rejected {_pct(p['rejected'], p['rendered'])} ({p['templates']} paraphrased templates; "
        f"{p['unchanged']} unchanged, {p['na']} n/a, {p['original_not_verified']} on decisions whose original "
        "was not verified, not counted)"
    )
    print("  by kind of edit (caught/mutated):")
    for c, r in m["categories"].items():
        ops = ", ".join(f"{o} {a}/{b}" for o, (a, b) in sorted(r.get("by_operator", {}).items()))
        print(f"    {c:<11} {ops}")
    for c, exs in m["misses"].items():
        print(f"\n  misses: {c} ({m['miss_counts'][c]} in all)")
        for ex in exs:
            _print_example("MISS", ex)
    if m["paraphrase_rejections"]:
        print(f"\n  paraphrases rejected ({len(m['all_paraphrase_rejections'])} in all)")
        for ex in m["paraphrase_rejections"]:
            _print_example("REJECTED PARAPHRASE", ex)


def _print_example(what, ex):
    head = f"    {what}: {ex['template']} on {ex['kind']}, decision {ex['decision']}"
    if ex.get("mutation"):
        head += f", mutation {ex.get('source')}:{ex['mutation']}"
    print(head)
    print(f"      text: {ex['text']}")
    if ex.get("original"):
        print(f"      original: {ex['original']}")
    if ex.get("twin_text"):
        print(f"      twin: {ex['twin_text']}")
    for s, st in ex.get("sentences", [])[:4]:
        print(f"      [{st}] {s[:300]}")
    for c in ex.get("contradicted", [])[:4]:
        print(f"      contradicted {c[0]} {c[1]!r} rule={c[3]}: {c[4][:200]}")
    for c in ex.get("claims", [])[:8]:
        print(f"      claim {c[0]} {c[1]!r} {c[2]} rule={c[3]}: {c[4][:160]}")
