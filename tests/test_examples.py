"""Every example runs with a tiny budget (CleanRL-style subprocess smoke tests)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"


def run(args, env=None, timeout=300):
    res = subprocess.run(
        [sys.executable, *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=ROOT,
        env={**os.environ, **(env or {})},
    )
    assert res.returncode == 0, res.stderr[-2000:]
    return res.stdout


@pytest.mark.slow
def test_sb3_cartpole():
    out = run([str(EX / "sb3_cartpole.py"), "--timesteps", "300"])
    assert out.count("The policy chose push_") == 5 and "additivity gap" in out


@pytest.mark.slow
def test_cleanrl_style():
    out = run([str(EX / "cleanrl_style.py"), "--steps", "300"])
    assert "rather than" in out and "global: Over 3 states" in out


@pytest.mark.slow
def test_cleanrl_gru_over_a_window(tmp_path):
    out = run([str(EX / "cleanrl_gru.py"), "--steps", "300", "--out", str(tmp_path / "gru")])
    assert "per step: {'t-3'" in out and out.count("[verified]") == 3 and out.count("said as trends:") == 3
    assert (tmp_path / "gru" / "heatmap.png").stat().st_size > 5000


@pytest.mark.slow
def test_atari_cnn_and_its_cli_with_nothing_installed(tmp_path):
    out = run([str(EX / "atari_cnn.py"), "--out", str(tmp_path / "ex")])
    assert "strongest patches: ['patch[" in out and (tmp_path / "ex" / "image.png").stat().st_size > 5000
    xairl = str(Path(sys.executable).with_name("xairl"))
    res = subprocess.run(
        [
            xairl,
            "explain",
            "--policy",
            f"{EX / 'atari_cnn.py'}:make_policy",
            "--policy-arg",
            "seed=1",
            "--states",
            str(tmp_path / "ex" / "states.npy"),
            "--background",
            str(tmp_path / "ex" / "background.npy"),
            "--out",
            str(tmp_path / "rep"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
    )
    assert res.returncode == 0, res.stderr[-2000:]
    for name in ("explanations.jsonl", "report.html", "beeswarm.png", "image.png"):
        assert (tmp_path / "rep" / name).stat().st_size > 0, name
    first = (tmp_path / "rep" / "explanations.jsonl").read_text().splitlines()[0]
    assert '"chosen":"' in first and '"obs[3,83,83]"' in first


@pytest.mark.slow
def test_continuous_actor():
    out = run([str(EX / "continuous_actor.py"), "--timesteps", "200"])
    assert "[continuous, verified=True" in out and "Torque was set to" in out
    assert "[value, verified=True" in out and "The Q estimate was" in out and "chose" not in out


@pytest.mark.slow
def test_custom_prompt():
    out = run([str(EX / "custom_prompt" / "run.py")])
    assert "explain_action.yaml ok" in out and "one_liner.yaml ok" in out
    assert "explain_action: Chose " in out and "[verified=True]" in out and ", mainly because of" in out


@pytest.mark.slow
def test_my_plugin_installs_and_registers(tmp_path):
    """pip installs the example plugin into its own folder; the entry point makes xairl find it."""
    target = tmp_path / "site"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "-q",
            "--no-deps",
            "--no-build-isolation",
            "--target",
            str(target),
            str(EX / "my_plugin"),
        ],
        check=True,
        capture_output=True,
        timeout=300,
    )
    env = {"PYTHONPATH": str(target), "XAIRL_LOAD_PLUGINS": "my-plugin"}
    out = run(["-m", "xairl.cli", "plugins"], env)
    assert (
        "my-plugin\n  attributor: occlusion\n  command: thermostat\n  narrator: shortest\n  policy: thermostat\n"
        "  prompt directory: "
    ) in out
    out = run(["-m", "xairl.cli", "thermostat", "--temperature", "15"], env)
    assert out.startswith("The thermostat chose heat: the room temperature (15 degC, cold) pushed toward it by +")
    out = run(
        [
            "-m",
            "xairl.cli",
            "explain",
            "--policy",
            "thermostat",
            "--n",
            "2",
            "--narrate",
            "--no-record",
            "--template",
            "thermostat",
        ],
        env,
    )
    assert out.count("[verified") == 2
    # the plugin's attributor and narrator, with options validated against their own models
    out = run(
        [
            "-m",
            "xairl.cli",
            "explain",
            "--policy",
            "thermostat",
            "--method",
            "occlusion",
            "-o",
            "max_rows=64",
            "--n",
            "2",
            "--narrate",
            "--narrator",
            "shortest",
            "-n",
            "max_sentences=1",
            "--no-record",
        ],
        env,
    )
    assert out.count("[verified") == 2 and out.count("; shortest]") == 2
    rows = [line for line in out.splitlines() if not line.startswith("    account: ")]
    for line in rows[1::2]:  # one sentence per narrative
        assert line.strip().count(". ") == 0 and line.strip().endswith(".")
