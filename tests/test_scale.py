"""The Ray engine (issue 28) on a local Ray started by the test (2 workers, loopback only): the same Parquet parts,
bit for bit, as the local engine, resume included; and the local engine never imports Ray."""

import subprocess
import sys

import numpy as np
import pytest

from xairl.cli import main
from xairl.runs.stream import explain_to_parquet, read_parquet
from xairl.toy import toy_policy

ray = pytest.importorskip("ray", reason="the Ray engine is the 'scale' extra (make test installs it)")
POLICY = toy_policy()


@pytest.fixture(scope="module")
def local_ray():
    """One local Ray for the module (2 CPUs, loopback only): the engine uses a running Ray and leaves it running."""
    ray.init(
        num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level="ERROR", _node_ip_address="127.0.0.1"
    )
    yield
    ray.shutdown()


@pytest.mark.slow
def test_ray_engine_writes_the_local_engines_bits_and_resumes(tmp_path, local_ray, capsys):
    """Resume on Ray as on the local engine (issue 51, item 2): lost parts are explained, a bit-flipped one is
    explained again to the same bits, a stray one is refused by name."""
    from xairl.runs.scale import explain_on_ray

    states = tmp_path / "s.npy"
    np.save(states, POLICY.background(1_200, seed=4))  # six chunks of 200
    bg = POLICY.background(30)
    explain_to_parquet(POLICY, states, tmp_path / "local", background=bg, chunk_size=200, progress=False)
    summary = explain_on_ray(POLICY, states, tmp_path / "ray", background=bg, chunk_size=200, workers=2)
    local, distributed = (read_parquet(tmp_path / d / "explanations.parquet") for d in ("local", "ray"))
    assert np.array_equal(local.values, distributed.values) and np.array_equal(local.outputs, distributed.outputs)
    assert summary.n == 1_200 and ray.is_initialized()  # a running Ray is used, and left running
    assert (tmp_path / "local" / "summary.json").read_text() == (tmp_path / "ray" / "summary.json").read_text()
    parts = sorted((tmp_path / "ray" / "explanations.parquet").glob("part-*.parquet"))
    for part in parts[2:4]:  # as if the run had been killed before these chunks were written
        part.unlink()
    whole = parts[1].read_bytes()
    middle = len(whole) // 2
    parts[1].write_bytes(whole[:middle] + bytes([whole[middle] ^ 4]) + whole[middle + 1 :])  # a flipped bit
    stray = parts[0].with_name("part-000000000007.parquet")
    stray.write_bytes(parts[0].read_bytes())
    argv = [
        "explain",
        "--states",
        str(states),
        "--out",
        str(tmp_path / "ray"),
        "--format",
        "parquet",
        "--engine",
        "ray",
        "--workers",
        "2",
        "--chunk-size",
        "200",
        "--resume",
    ]
    capsys.readouterr()
    assert main(argv + ["--background-size", "30"]) == 2  # a stray part: refused by name, nothing explained
    assert "part-000000000007.parquet: not a part of this run" in capsys.readouterr().err
    stray.unlink()
    assert main(argv + ["--background-size", "31"]) == 2  # another background than the run's: refused
    assert main(argv + ["--background-size", "30"]) == 0  # the same run (the sampler's 30 states): resumed
    again = read_parquet(tmp_path / "ray" / "explanations.parquet")
    assert np.array_equal(again.values, local.values) and parts[1].read_bytes() == whole  # every state once


@pytest.mark.slow
def test_ray_reads_parquet_by_row_group_and_csv_once_rewritten(tmp_path, local_ray):
    import pyarrow as pa
    import pyarrow.parquet as pq

    from xairl.runs.scale import STAGED, explain_on_ray
    from xairl.toy import FEATURES

    states, bg = POLICY.background(1_000, seed=5), POLICY.background(20)
    pq.write_table(
        pa.table({f: states[:, j] for j, f in enumerate(FEATURES)}), tmp_path / "s.parquet", row_group_size=120
    )  # row groups that do not fall on the chunks' bounds
    (tmp_path / "s.csv").write_text(
        ",".join(FEATURES) + "\n" + "\n".join(",".join(repr(float(v)) for v in row) for row in states)
    )
    local = explain_to_parquet(POLICY, states, tmp_path / "local", background=bg, chunk_size=400, progress=False)
    for name in ("s.parquet", "s.csv"):
        summary = explain_on_ray(
            POLICY, tmp_path / name, tmp_path / name.replace(".", "_"), background=bg, chunk_size=400, workers=2
        )
        assert summary.n == local.n == 1_000
        assert np.array_equal(
            read_parquet(tmp_path / name.replace(".", "_") / "explanations.parquet").values,
            read_parquet(tmp_path / "local" / "explanations.parquet").values,
        ), name
        assert not (tmp_path / name.replace(".", "_") / STAGED).exists()  # the CSV's rewrite is removed


@pytest.mark.slow
def test_ray_reports_a_users_error_in_one_line_and_keeps_what_was_written(tmp_path, local_ray):
    import pyarrow as pa
    import pyarrow.parquet as pq

    from xairl.errors import InputError
    from xairl.runs.scale import STAGED, explain_on_ray
    from xairl.toy import FEATURES

    states = POLICY.background(2_500, seed=6).astype(float)
    states[1_700, 2] = np.nan  # found by the worker that reads rows 1000..1999, not by the driver
    pq.write_table(
        pa.table({f: states[:, j] for j, f in enumerate(FEATURES)}), tmp_path / "s.parquet", row_group_size=500
    )
    with pytest.raises(InputError, match=r"rows 1000\.\.1999 contain 1 NaN/inf value") as err:
        explain_on_ray(
            POLICY, tmp_path / "s.parquet", tmp_path / "o", background=POLICY.background(20), chunk_size=1000, workers=2
        )
    assert "\n" not in str(err.value) and "Ray" not in str(err.value)
    assert sorted(p.name for p in (tmp_path / "o" / "explanations.parquet").glob("*.parquet")) == [
        "part-000000000000.parquet",
        "part-000000002000.parquet",
    ]  # the good chunks stay, for --resume
    (tmp_path / "s.csv").write_text(",".join(FEATURES) + "\n")  # a header and no state
    with pytest.raises(InputError, match="holds no state"):
        explain_on_ray(POLICY, tmp_path / "s.csv", tmp_path / "o2", background=POLICY.background(20))
    assert not (tmp_path / "o2" / STAGED).exists() and not list((tmp_path / "o2").glob(".*.part"))


@pytest.mark.slow
def test_narrations_on_ray_are_the_narrations_here_in_order(local_ray):
    import xairl
    from xairl.runs.scale import narrate_on_ray

    bg = POLICY.background(20)
    exp = xairl.explain(POLICY, POLICY.background(6, seed=8), background=bg)
    here = [xairl.narrate(exp, i, policy=POLICY, background=bg) for i in (5, 0, 3)]
    there = narrate_on_ray(exp, [5, 0, 3], narrator="template", workers=2, policy=POLICY, background=bg)
    assert [n.text for n in there] == [n.text for n in here] and [n.index for n in there] == [5, 0, 3]
    assert all(n.verified for n in there) and [n.confidence for n in there] == [n.confidence for n in here]
    with pytest.raises(xairl.XairlError, match=r"indices must lie in 0\.\.5"):
        narrate_on_ray(exp, [6], narrator="template", policy=POLICY)  # refused here, before any worker starts
    with pytest.raises(xairl.XairlError, match="unknown narrator 'nope'"):
        narrate_on_ray(exp, narrator="nope")
    with pytest.raises(xairl.XairlError, match="unknown template 'nope'"):  # raised in a worker, shown as itself
        narrate_on_ray(exp, [0], narrator="template", template="nope", policy=POLICY)


@pytest.mark.slow
def test_the_local_engine_imports_no_ray(tmp_path):
    code = (
        "import sys, numpy as np; from xairl.toy import toy_policy; from xairl.runs.stream import explain_to_parquet; "
        f"p = toy_policy(); explain_to_parquet(p, p.background(100), {str(tmp_path / 'o')!r}, progress=False); "
        "print('ray' in sys.modules)"
    )
    assert (
        subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
        == "False"
    )
