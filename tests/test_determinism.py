"""Seeded runs give bit-identical explanations and narratives, also across processes."""
import subprocess
import sys

CODE = """
import hashlib, json, xairl
from xairl.toy import toy_policy
p = toy_policy()
x, bg = p.background(6, seed=3), p.background(40, seed=4)
h = hashlib.sha256()
for m, o in (("deep_shap", None), ("kernel_shap", {"nsamples": 30, "seed": 7}), ("exact", None),
             ("integrated_gradients", None)):
    e = xairl.explain(p, x, background=bg, method=m, options=o)
    h.update(e.to_json().encode())
    for i in range(3):
        h.update(xairl.narrate(e, i, policy=p, background=bg).text.encode())
h.update(xairl.narrate(e, 0, narrator="local_lm", policy=p).text.encode())
print(h.hexdigest())
"""


def test_two_processes_same_bits():
    from xairl.narrators.local_lm import load_model

    load_model()  # convert the model once into this session's cache; the two processes then load the copy
    runs = [subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, check=True).stdout.strip()
            for _ in range(2)]
    assert len(runs[0]) == 64 and runs[0] == runs[1]
