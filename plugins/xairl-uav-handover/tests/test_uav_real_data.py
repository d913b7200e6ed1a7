"""Real flight data (../shared/data, never committed) and the report. Skips cleanly where the data is absent."""

import contextlib
import io
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from xairl import InputError
from xairl.cli import main
from xairl.explanations import display
from xairl.plugin import StateRecord
from xairl_uav_handover.baselines import CHMConfig
from xairl_uav_handover.calibration import agreement_rows, outside
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.exports import load_flight, load_folder
from xairl_uav_handover.policy import dqn_decision_states, load_checkpoint
from xairl_uav_handover.real_data import agreement, baltaci_rate_by_altitude, chm_handovers, walk

DATA = Path(__file__).resolve().parents[3].parent / "shared" / "data"
UKM = DATA / "ukm-uav-lte" / "raw"
BALTACI = DATA / "baltaci-imc22-handovers"
needs_data = pytest.mark.skipif(not UKM.is_dir(), reason="../shared/data/ukm-uav-lte is not here")


@pytest.mark.slow
@needs_data
def test_load_one_flight():
    f = load_flight(UKM / "100m.csv")
    assert f.altitude_m == 100 and len(f.t) > 1000 and (np.diff(f.t) > 0).all()
    assert -98 <= f.rsrp.min() and f.rsrp.max() <= -50
    assert np.abs(f.xy).max() < 2000  # local metres around the campus
    assert f.observed_handovers == int((np.diff(f.pci) != 0).sum()) > 10
    w = walk(f)
    assert w.states.shape == (len(f.t), 13) and (w.serving == f.pci).all()
    assert int((w.next_serving != w.serving).sum()) == f.observed_handovers
    assert (w.states[:, 5] == f.rsrp).all(), "candidate 0 is the network's serving cell"
    for state, cand in zip(w.states, w.candidates):
        assert (np.diff(state[6 : 5 + len(cand)]) <= 0).all(), "measured neighbours sorted by RSRP"
        assert (state[9 + len(cand) :] == -24.0).all(), "empty slots at the detection limit"
    assert 0 < (w.queue_bits > 0).mean() < 1 and w.queue_bits.max() <= SimConfig().buffer.q_max_bits


@needs_data
def test_open_loop_agreement_on_known_deciders():
    w = walk(load_flight(UKM / "100m.csv"))
    stay = agreement([w], lambda _w: lambda s, c, t: 0)
    assert (stay.proposals, stay.stay_agreement, stay.handover_agreement) == (0, 1.0, 0.0)
    assert stay.network_handovers == int((w.next_serving != w.serving).sum())
    follow = dict(zip(w.t.tolist(), w.next_serving.tolist()))  # an oracle that does what the network did next
    oracle = agreement([w], lambda _w: lambda s, c, t: c.index(follow[t]) if follow[t] in c else 0)
    assert oracle.stay_agreement == 1.0 and oracle.target_agreement == oracle.handover_agreement > 0.5
    assert oracle.new_proposals == oracle.proposals  # each of its proposals is carried out, so none stands
    # a decider that always proposes the strongest neighbour: one standing proposal per (serving, neighbour) pair
    eager = agreement([w], lambda _w: lambda s, c, t: 1 if len(c) > 1 else 0)
    runs = sum(
        1
        for i in range(len(w.t) - 1)
        if len(w.candidates[i]) > 1
        and (i == 0 or len(w.candidates[i - 1]) < 2 or w.candidates[i - 1][:2] != w.candidates[i][:2])
    )
    assert eager.new_proposals == runs < eager.proposals
    assert chm_handovers(load_flight(UKM / "100m.csv")) > 0


@needs_data
def test_chm_replayed_on_real_measurements():
    f = load_flight(UKM / "100m.csv")
    n = chm_handovers(f)
    assert 0 < n < len(f.t) / 2  # A3 needs two consecutive samples 2 dB above the serving cell
    assert chm_handovers(f, CHMConfig(offset_db=6.0)) < n  # a larger offset hands over less


@pytest.fixture(scope="module")
def ukm_walks():
    """The committed checkpoint and every UKM flight walked under its simulator settings (shared: walking is slow)."""
    ckpt = load_checkpoint()
    return ckpt, [walk(f, ckpt.sim_config) for f in load_folder(UKM)[0]]


@pytest.mark.slow
@needs_data
@pytest.mark.xfail(
    strict=True,
    reason="issue 11's target, lost with issue 53's simulator: 37 % of real states have a feature outside the "
    "simulated 0.5-99.5 % range (was 3 %), above all RSRQ: the real cells reach -6 dB and leave more candidate slots "
    "empty (docs/uav-reference.md, 'Against the real flights')",
)
def test_real_states_lie_in_the_training_distribution(ukm_walks):
    ckpt, walks = ukm_walks
    real = np.concatenate([w.states for w in walks])
    sim = dqn_decision_states(ckpt, 5000, seed=2, epsilon=0.5, n_flights=256)
    assert outside(real, sim).any(axis=1).mean() <= 0.05


@pytest.mark.slow
@needs_data
def test_calibration_targets_on_the_real_flights(ukm_walks):
    """Issue 11's calibration, on all 29 UKM flights against the committed checkpoint (small simulated samples): the
    modelled real buffer full in < 20 % of real states, yet not always empty; open loop, the DQN starts new handover
    proposals at <= 2x the network's rate, and sometimes proposes the network's target cell at its handovers."""
    ckpt, walks = ukm_walks
    cfg = ckpt.sim_config
    q = np.concatenate([w.queue_bits for w in walks])
    assert np.mean(q >= cfg.buffer.q_max_bits) < 0.2 and np.mean(q > 0) > 0.02
    dqn, a3, _ = agreement_rows(walks, ckpt, cfg)
    assert dqn.new_proposals_per_min <= 2 * dqn.network_per_min
    # the paper's DQN seldom hands over: at 4.1 % of the network's handovers it proposes the network's target cell
    # (A3 8.5 %); issue 26's target (at least 0.8 x A3) was the priced DQN's (docs/uav-reference.md)
    assert dqn.target_agreement_pct > 0 and a3.target_agreement_pct > 0


@needs_data
def test_malformed_files_name_file_and_column(tmp_path):
    src = (UKM / "100m.csv").read_text().splitlines()
    (tmp_path / "20m.csv").write_text("\n".join(src[:1]) + "\n")  # truncated: a header and nothing else
    header = src[0].split(",")
    k = header.index("RS SNR")
    (tmp_path / "30m.csv").write_text(
        "\n".join(",".join(c for i, c in enumerate(line.split(",")) if i != k) for line in src[:400])
    )
    j = header.index("RSRP (LTE pcell)")
    rows = [line.split(",") for line in src[1:400]]
    for r in rows:
        if len(r) > j and r[j]:
            r[j] = str(float(r[j]) * -1000)  # wrong units
    (tmp_path / "40m.csv").write_text("\n".join([src[0]] + [",".join(r) for r in rows]))
    (tmp_path / "noheight.csv").write_text("\n".join(src[:400]))
    shutil.copy(UKM / "25m.csv", tmp_path / "25m.csv")
    for name, match in (
        ("20m.csv", "no rows with a parseable Time"),
        ("30m.csv", "missing column 'RS SNR'"),
        ("40m.csv", r"'RSRP \(LTE pcell\)' has median .* wrong units"),
        ("noheight.csv", "altitude is read from the file name"),
    ):
        with pytest.raises(InputError, match=match) as info:
            load_flight(tmp_path / name)
        assert name in str(info.value)
    flights, bad = load_folder(tmp_path)
    assert [f.name for f in flights] == ["25m.csv"] and len(bad) == 4


@pytest.mark.skipif(not BALTACI.is_dir(), reason="../shared/data/baltaci-imc22-handovers is not here")
def test_baltaci_rates():
    bins, rate, n = baltaci_rate_by_altitude(BALTACI)
    assert list(bins) == list(range(0, 130, 10)) and n > 2000 and (rate >= 0).all() and rate.sum() > 0


@pytest.fixture(scope="module")
def sim_report(tmp_path_factory):
    """The smallest report without real data (one flight in Table I, 6 states, no flight at a glance); the report's
    other tests read one report with real flights (conftest's ``real_report``)."""
    out = tmp_path_factory.mktemp("sim") / "rep"
    argv = ["report", "--plugin", "uav-handover", "--n", "6", "-o", "flights=1", "-o", "timelines=0", "--narrate"]
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stderr(io.StringIO()) as err:
        mp.setattr(display, "EVERY", 0.01)  # each step is said, however short
        code = main([*argv, "--no-robustness", "--out", str(out)])
    assert code == 0, err.getvalue()[-2000:]
    (out.parent / "stderr.txt").write_text(err.getvalue())
    return out


@pytest.mark.slow
def test_a_report_without_real_data_says_its_steps(sim_report):
    """The report's steps without the real flights, each said once and in order (with them: test_uav_report.py)."""
    said = (sim_report.parent / "stderr.txt").read_text().splitlines()
    starts = [
        line[len("xairl: ") : -len(" ...")] for line in said if line.startswith("xairl: ") and line.endswith(" ...")
    ]
    steps = ["building the uav-handover report's content", "Table I: CHM, SA-MRO and the DQN on 1 simulated flight"]
    steps += ["simulating and explaining the flights at a glance", "drawing the figures", "narrating 6 decisions"]
    quick = {steps[2]}  # no flight at a glance here: said only when the heartbeat's thread is in time
    assert [s for s in starts if not s.startswith("explaining")] == [s for s in steps if s in starts], starts
    assert set(steps) - set(starts) <= quick, starts


@pytest.mark.slow
def test_report_without_real_data(sim_report):
    out = sim_report
    html = (out / "report.html").read_text()
    assert "Table I" in html and html.count("data:image/png;base64,") >= 3
    assert "&#10003; verified" in html and "confidence" in html
    assert "Calibration" not in html and "Open-loop agreement" not in html  # the real flights' sections
    lines = (out / "explanations.jsonl").read_text().splitlines()
    assert len(lines) == 6
    rec = StateRecord.model_validate_json(lines[0])
    assert rec.dataset == "simulated" and set(rec.values) >= {"buffer_queue_size", "rsrp_0"}
    schema = json.loads((out / "explanations.schema.json").read_text())
    assert "values" in schema["properties"]


@pytest.mark.slow
@needs_data
def test_the_uplink_reaches_the_measured_throughput_on_held_out_flights():
    """Issue 53: P0 and the other cells' uplink load were fitted on the even-named UKM flights; on the odd-named
    ones the modelled uplink's median capacity lies within 15 % of IMC'22's measured 37.7 Mbit/s (operator B)."""
    from xairl_uav_handover.calibration import split_flights
    from xairl_uav_handover.real_data import UplinkBuffer
    from xairl_uav_handover.uplink import capacity_bps

    cfg = SimConfig()
    _, held = split_flights(load_folder(UKM)[0])
    caps = []
    for f in held:
        link = UplinkBuffer(cfg, f.altitude_m, seed=0, flight=f.name)
        caps += [capacity_bps(cfg, link.sinr_db(float(r), p)) for r, p in zip(f.rsrp[::10], f.pci[::10])]
    assert abs(np.median(caps) / 37.7e6 - 1) <= 0.15, np.median(caps) / 1e6
