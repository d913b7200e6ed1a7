"""``xairl explain --counterfactual``: under each decision (the table, or its narrative with ``--narrate``), what would
have had to differ for the policy to choose otherwise: the smallest change of at most ``--max-changes`` features
within the bounds (:func:`xairl.counterfactual`, every result re-run through the policy), the action it then takes
and its margin, or why none is reachable. The decisions are searched in one batch, guided by the explanation the
command computed; ``--counterfactual-target`` asks for the runner-up (default), a named action or ``any``."""

from __future__ import annotations

import argparse

from xairl.errors import InputError


def counterfactual_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--counterfactual",
        action="store_true",
        help="under each decision, the smallest change of at most --max-changes features (within the data's range "
        "and the declared bounds) that makes the policy choose another action, checked by running it",
    )
    p.add_argument(
        "--counterfactual-target",
        default=None,
        metavar="NAME|INDEX|any",
        help="with --counterfactual: the action to reach, by name or index (default: the runner-up), or 'any' other "
        "action",
    )
    p.add_argument(
        "--counterfactual-past",
        action="store_true",
        help="with --counterfactual, a window policy: change its past observations' slots too (default: only the "
        "newest step's; a past slot changed alone is a history the present state cannot have)",
    )
    p.add_argument(
        "--max-changes",
        type=int,
        choices=(1, 2),
        default=2,
        help="with --counterfactual: at most this many features change (default 2)",
    )


def asked(args, policy) -> bool:
    """Whether --counterfactual (or --counterfactual-target or --counterfactual-past alone) was given, its target checked against the policy's
    actions before any state is explained, in every format (one line naming the known actions); and refused with
    --format parquet, whose chunks are streamed to disk without a search."""
    if not _on(args):
        return False
    target = _target(args, policy)
    if target is not None and target != "any":
        from xairl.counterfactuals.goals import action_index

        action_index(policy, target)
    if args.format == "parquet":
        raise InputError(
            "--counterfactual is not searched when explanations stream into Parquet (--format parquet, or --out above "
            "the streaming size); drop --counterfactual, or explain fewer states as a table, jsonl or report."
        )
    return True


def _on(args) -> bool:
    """--counterfactual, or one of its own options alone (--counterfactual-target, --counterfactual-past), turns the
    search on: an option of the search is never silently ignored."""
    return bool(args.counterfactual or args.counterfactual_target is not None or args.counterfactual_past)


def _target(args, policy):
    """The search's target of ``--counterfactual-target``: None (the runner-up), 'any', an action's name or index."""
    target = args.counterfactual_target
    target = None if target in (None, "", "runner-up") else target
    if target is not None and target not in policy.action_names and target.lstrip("-").isdigit():
        target = int(target)  # an action's index, as the docs say ('--counterfactual-target 2')
    return target


def search(args, policy, exp, background):
    """Each decision's :class:`xairl.Counterfactuals` (a tuple), or None without ``--counterfactual`` (the target
    alone turns it on)."""
    if not _on(args):
        return None
    if exp.output != "actions":
        raise InputError(
            f"--counterfactual searches for another action: policy '{policy.name}' outputs {exp.output}, not "
            "discrete actions; use xairl.counterfactual(..., target=xairl.Threshold(...)) from Python."
        )
    from xairl.counterfactuals import counterfactual

    target = _target(args, policy)
    return counterfactual(
        policy,
        exp.states,
        index=None,
        target=target,
        max_changes=args.max_changes,
        background=background,
        explanation=exp,
        n=3,  # alternatives, so that one still flips once its values are written as the words write them
        past=args.counterfactual_past,
    )


def said(found, i: int) -> dict:
    """narrate's ``counterfactual`` argument for decision ``i``: its answer, for the template's sentence (which says
    nothing of a miss)."""
    return {} if found is None else {"counterfactual": found[i]}


def summaries(found, policy) -> list[dict] | None:
    """Each decision's answer as plain data (:func:`xairl.counterfactual_facts.as_written`): its values as the
    narratives write them, each re-run through the policy as written, so that the block and the sentence agree."""
    if found is None:
        return None
    from xairl.counterfactual_facts import as_written
    from xairl.outputs.report_counterfactuals import writer

    write = writer(policy)
    return [as_written(policy, r, write) for r in found]


def block(cf: dict) -> str:
    """The terminal's lines of one decision: a heading, then one row per counterfactual (or why there is none)."""
    from xairl.explanations.display import counterfactual_meta, counterfactual_text

    rows = "\n".join(f"      {line}" for line in counterfactual_text(cf))
    return f"    what would have changed it ({counterfactual_meta(cf, chosen=False)}):\n{rows}"
