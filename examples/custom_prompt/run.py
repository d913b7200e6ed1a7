"""Override a built-in template and add a new one, then check and use them.

Run: python examples/custom_prompt/run.py
"""

from pathlib import Path

import xairl

here = Path(__file__).parent / "prompts"
for path in sorted(here.glob("*.yaml")):
    problems = xairl.plugin.check_template(path)
    print(path.name, "ok" if not problems else problems)
policy = xairl.get_policy("toy")
exp = xairl.explain(policy, policy.background(2, seed=4))
for name in ("explain_action", "one_liner"):
    n = xairl.narrate(exp, 0, template=name, policy=policy, prompt_dirs=[here])
    print(f"{name}: {n.text}  [verified={n.verified}]")
