"""Which templates benchmarks/bench_templates.py renders: the frozen and held-out sets (each with its MANIFEST and
the twins of its wrong templates), the built-ins and the UAV plugin's handover, each with the policy kinds whose
output it declares and what `xairl prompts check` says of its literal claim words."""

from __future__ import annotations

from pathlib import Path

import yaml

from xairl.templates import prompts as xprompts

DATA = Path(__file__).resolve().parent / "data" / "templates"
KINDS = ("flat", "dict", "image", "continuous", "value", "uav")
OUTPUT_OF = {"flat": "actions", "dict": "actions", "image": "actions", "uav": "actions"} | {
    "continuous": "continuous",
    "value": "value",
}


def read_template(path: Path) -> dict:
    return yaml.safe_load(path.read_text())


def template_kinds(spec: dict, kinds) -> list[str]:
    outs = spec.get("outputs") or ["actions", "continuous", "value"]
    return [k for k in kinds if OUTPUT_OF[k] in outs]


def builtin_templates(kinds) -> list[dict]:
    """The built-ins (prompts/*.yaml) and the UAV plugin's handover (on the UAV kind only)."""
    found = []
    for path in sorted(xprompts.builtin_dir().glob("*.yaml")):
        spec = read_template(path)
        found.append({"name": spec["name"], "path": path, "spec": spec, "kinds": template_kinds(spec, kinds)})
    from xairl.registry.plugins import prompt_dirs

    for _, folder in prompt_dirs():
        for path in sorted(Path(folder).glob("*.yaml")):
            spec = read_template(path)
            if spec["name"] == "handover":
                found.append(
                    {"name": "handover", "path": path, "spec": spec, "kinds": [k for k in kinds if k == "uav"]}
                )
    return found


def flagged(path: Path) -> list[str]:
    """What `xairl prompts check` says of the template's literal claim words (file:line, word, filter to use)."""
    from xairl.narrators.battery import undeclared

    return undeclared(xprompts.load(path))


def set_templates(name: str, kinds) -> list[dict]:
    folder = DATA / name
    manifest = yaml.safe_load((folder / "MANIFEST.yaml").read_text())
    out = []
    for t in manifest["templates"]:
        path = folder / t["file"]
        spec = read_template(path)
        twin = DATA / "twins" / name / t["file"]
        out.append(
            {
                "name": spec["name"],
                "path": path,
                "spec": spec,
                "flagged": flagged(path),
                "correct": bool(t["correct"]),
                "kinds": template_kinds(spec, kinds),
                "twin": twin if not t["correct"] else None,
                "error": t.get("error"),
            }
        )
    return out
