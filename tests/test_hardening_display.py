"""Issue 51, round 3 of hardening, the display side: the review page hangs up on clients that trickle (item 7), the
figures keep their labels apart and inside, write values in the feature's unit and give actions their own marks
(14), the region beeswarm is readable (13), every figure names its view (15), and notebooks get no 'IProgress not
found' (18)."""

import itertools
import socket
import subprocess
import sys
import time
from dataclasses import replace

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

import xairl
from xairl import plots
from xairl.outputs.feedback import FeedbackStore
from xairl.outputs.review import serve_in_thread
from xairl.policies.policy import FeatureInfo
from xairl.toy import toy_policy

# --- item 7: a total deadline per connection and a cap on connections (loopback only) ---------------------------


@pytest.fixture
def server(tmp_path):
    """Starts a review server over an empty store with the given limits; every one started is shut down after."""
    started = []

    def start(**limits):
        srv, _ = serve_in_thread(FeedbackStore(tmp_path / "fb.sqlite"), **limits)
        started.append(srv)
        return srv, srv.server_address[1]

    yield start
    for srv in started:
        srv.shutdown()


def _get(port, timeout=5.0):
    """A whole GET / at once: (status, body); status 0 when the connection closed unanswered."""
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
        data = b""
        while chunk := s.recv(65536):
            data += chunk
    head, _, body = data.partition(b"\r\n\r\n")
    return (int(head.split()[1]) if data else 0), body.decode()


def _closed(s: socket.socket) -> bool:
    """Whether the server hung up on ``s`` (end of stream or reset), without waiting."""
    s.setblocking(False)
    try:
        return s.recv(1024) == b""
    except BlockingIOError:
        return False
    except OSError:
        return True
    finally:
        s.setblocking(True)


def _wait_until(condition, limit: float) -> bool:
    end = time.monotonic() + limit
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.05)
    return condition()


@pytest.mark.slow
def test_clients_that_trickle_are_hung_up_on_at_the_deadline_and_a_normal_client_is_served(server):
    deadline, n = 1.5, 5
    srv, port = server(timeout=10.0, deadline=deadline, max_connections=n + 2)  # a read timeout alone never fires
    stream = f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nX-Slow: ".encode() + b"a" * 10_000  # never ends
    opened = time.monotonic()
    slow = [socket.create_connection(("127.0.0.1", port), timeout=5) for _ in range(n)]
    cut: dict[int, float] = {}
    served = None
    sent = 0
    ceiling = deadline + 15  # generous: what is checked is that they are cut, and not before the deadline
    while len(cut) < n and time.monotonic() - opened < ceiling:  # one byte per client every 50 ms
        for k, s in enumerate(slow):
            if k in cut:
                continue
            try:
                s.send(stream[sent : sent + 1])
            except OSError:
                cut[k] = time.monotonic() - opened
                continue
            if _closed(s):
                cut[k] = time.monotonic() - opened
        sent += 1
        if served is None and time.monotonic() - opened > deadline / 2:
            assert srv.open_connections == n  # all the slow ones are being held: this is during the trickle
            served = _get(port)
        time.sleep(0.05)
    for s in slow:
        s.close()
    assert served is not None and served[0] == 200 and "Nothing to review" in served[1]
    assert sorted(cut) == list(range(n)), f"hung up on {len(cut)} of {n} within {ceiling} s"
    assert min(cut.values()) >= deadline  # not before the deadline (timed from before the connection)
    assert _wait_until(lambda: srv.open_connections == 0, 3)  # every thread freed


@pytest.mark.slow
def test_connections_beyond_the_cap_are_answered_503_until_the_held_ones_pass_their_deadline(server):
    deadline, cap = 1.0, 3
    srv, port = server(timeout=10.0, deadline=deadline, max_connections=cap)
    held = [socket.create_connection(("127.0.0.1", port), timeout=5) for _ in range(cap)]
    for s in held:
        s.sendall(b"GET / HT")  # and nothing more
    assert _wait_until(lambda: srv.open_connections == cap, 3)
    for _ in range(10):  # a flood beyond the cap: answered at once, no thread kept
        status, body = _get(port)
        assert status == 503 and "too many connections" in body
        assert srv.open_connections <= cap
    assert _wait_until(lambda: all(_closed(s) for s in held), deadline + 3)
    for s in held:
        s.close()
    assert _wait_until(lambda: srv.open_connections == 0, 3)
    assert _get(port)[0] == 200


@pytest.mark.slow
def test_a_request_cut_at_its_deadline_is_not_answered(server):
    """Headers cut short by the hang-up are not taken for a whole request (no page rendered for a slow client)."""
    _, port = server(timeout=10.0, deadline=0.5)
    s = socket.create_connection(("127.0.0.1", port), timeout=5)
    s.sendall(f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nX-Slow: abc".encode())
    data = b""
    try:
        while chunk := s.recv(65536):
            data += chunk
    except ConnectionResetError:
        pass
    s.close()
    assert data == b""


def test_review_limits_must_be_positive(tmp_path):
    from xairl.errors import InputError
    from xairl.outputs.review import make_server

    for limits in ({"deadline": 0}, {"max_connections": 0}, {"timeout": -1}):
        with pytest.raises(InputError, match="positive"):
            make_server(FeedbackStore(tmp_path / "fb.sqlite"), 0, **limits)


# --- items 13, 14, 15: figures that can be read -------------------------------------------------------------------

MARGIN, SCORE = "contribution to the margin over the runner-up", "contribution to the chosen action's score"


def _renderer(fig):
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def _boxes(texts, renderer):
    return [(t.get_text(), t.get_window_extent(renderer)) for t in texts if t.get_visible() and t.get_text()]


def _tick_labels(ax):
    """The tick labels drawn (those of ticks within the view limits; a locator also places some beyond them)."""
    out = []
    for axis, limits in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        lo, hi = sorted(limits)
        for tick in axis.get_major_ticks():
            if lo - 1e-9 * (hi - lo) <= tick.get_loc() <= hi + 1e-9 * (hi - lo):
                out += [t for t in (tick.label1, tick.label2) if t.get_visible() and t.get_text()]
    return out


def _overlap(a, b, slack=0.5) -> bool:
    return a.x0 < b.x1 - slack and b.x0 < a.x1 - slack and a.y0 < b.y1 - slack and b.y0 < a.y1 - slack


def _inside(box, outer, slack=1.0) -> bool:
    return (
        box.x0 >= outer.x0 - slack
        and box.x1 <= outer.x1 + slack
        and box.y0 >= outer.y0 - slack
        and box.y1 <= outer.y1 + slack
    )


def _all_texts(fig):
    out = list(fig.texts)
    for ax in fig.axes:
        out += [ax.title, ax.xaxis.label, ax.yaxis.label, *ax.texts, *_tick_labels(ax)]
    return out


@pytest.fixture(scope="module")
def toy():
    """The toy policy, with a unit and a capacity declared for two of its features, and its explanation."""
    p = toy_policy()
    p = replace(
        p,
        features={
            **p.features,
            "speed": FeatureInfo("m/s", "speed"),
            "battery": FeatureInfo("kWh", "battery charge", capacity=4.0),
        },
    )
    return p, xairl.explain(p, p.background(16, seed=1), background=p.background(40, seed=2))


def _lopsided(n_features=10) -> xairl.Explanation:
    """One step far larger than the rest, and negative: its label falls beyond the plot's left edge unless kept in."""
    rng = np.random.default_rng(3)
    v = rng.normal(size=(4, n_features, 3))
    v[:, 0, 0], v[:, 0, 1] = -60.0, 0.0  # action 0 chosen by its other features, pulled far down by feature 0
    v[:, 1:, 0] += 9.0
    base = np.array([[150.0, 140.0, 0.0]] * 4)
    return xairl.Explanation(
        values=v,
        base_values=base,
        outputs=base + v.sum(axis=1),
        states=rng.normal(size=(4, n_features)) * 1e6,
        feature_names=[f"rsrq_{k}" for k in range(n_features)],
        action_names=["a", "b", "c"],
        method="test",
    )


@pytest.mark.parametrize("view", ["margin", "score"])
def test_waterfall_value_labels_stay_inside_the_plot_and_off_the_tick_labels(view, toy):
    for exp, i in ((_lopsided(), 0), (toy[1], 3)):
        fig = plots.waterfall(exp, i, view=view)
        r = _renderer(fig)
        ax = fig.axes[0]
        plot, whole = ax.get_window_extent(r), fig.bbox
        values = _boxes(ax.texts, r)
        assert len(values) == len(ax.patches)  # one label per step
        for text, box in values:
            assert _inside(box, plot), f"{text} lies outside the plot"
            for tick, tbox in _boxes(_tick_labels(ax), r):
                assert not _overlap(box, tbox), f"value {text} overlaps tick label {tick}"
        for text, box in _boxes(_all_texts(fig), r):
            assert _inside(box, whole), f"{text!r} is cut at the figure's edge"


def test_waterfall_writes_values_as_the_narratives_do_in_the_features_unit(toy):
    policy, exp = toy
    i = 2
    fig = plots.waterfall(exp, i, shown=5, policy=policy)
    labels = [t.label1.get_text() for t in fig.axes[0].yaxis.get_major_ticks()]
    j = {f: k for k, f in enumerate(exp.feature_names)}
    speed, battery = exp.states[i, j["speed"]], exp.states[i, j["battery"]]
    from xairl.facts import format_number as fmt

    assert f"speed = {fmt(speed)} m/s" in labels
    assert f"battery = {fmt(100 * battery / 4.0)} % full" in labels
    no_units = [t.label1.get_text() for t in plots.waterfall(_lopsided(), 0).axes[0].yaxis.get_major_ticks()]
    assert not [t for t in no_units if "e+" in t], no_units  # 1e6 is written out, as a narrative writes it
    narrative = xairl.narrate(exp, i, policy=policy, robustness=False)
    fact = (
        next(f for f in narrative.facts.features if f.name == "battery")
        if hasattr(narrative, "facts") and hasattr(narrative.facts, "features")
        else None
    )
    if fact is not None:  # the same text as the narrative's own fact
        assert f"battery = {fact.value_text}" in labels


def test_timeline_gives_actions_their_own_colours_and_markers(toy):
    _, exp = toy
    exp = replace(exp, outputs=exp.outputs + np.eye(exp.values.shape[2])[np.arange(16) % exp.values.shape[2]] * 1e3)
    assert len(set(exp.chosen.tolist())) >= 3
    fig = plots.timeline(exp, top=5)
    acts, lines = fig.axes[0], fig.axes[1]
    from matplotlib.colors import to_hex

    line_colours = {to_hex(line.get_color()) for line in lines.get_lines() if line.get_label()[:1] != "_"}
    assert len(line_colours) == 5
    marks, colours = [], set()
    for coll in acts.collections:
        colours |= {to_hex(c) for c in coll.get_facecolors()}
        marks.append(coll.get_paths()[0].vertices.round(3).tobytes())
    assert colours and not colours & line_colours, "an action is drawn in a feature's colour"
    assert len(colours) == len(set(exp.chosen.tolist())) == len(set(marks)), "each action its own colour and marker"


def test_a_decision_with_one_action_available_is_no_margin_of_an_action_over_itself(toy, tmp_path):
    """A mask leaving one action: its waterfall is the score's (as its card), and the report picks a real choice."""
    from xairl.outputs.report import _interesting

    _, exp = toy
    available = np.ones(exp.outputs.shape, dtype=bool)
    available[:3, 1:] = False  # states 0-2: only the first action
    exp = replace(exp, available=available)
    assert (exp.runner_up[:3] == exp.chosen[:3]).all()
    fig = plots.waterfall(exp, 0)
    assert "chosen action's score" in fig.axes[0].get_title() and "only action" in fig.axes[0].get_title()
    assert " over " not in fig.axes[0].get_xlabel()
    assert any(abs(float(t.get_text())) > 0 for t in fig.axes[0].texts)
    assert _interesting(exp) >= 3


def _long_regions(n_features=30) -> xairl.Explanation:
    rng = np.random.default_rng(0)
    names = [
        f"the 12x12 patch at rows {12 * (k % 7)} to {12 * (k % 7) + 11}, columns {12 * (k // 7)} to "
        f"{12 * (k // 7) + 11} of channel {k % 4}"
        for k in range(n_features)
    ]
    v = rng.normal(size=(40, n_features, 3)) * np.linspace(1, 0.01, n_features)[None, :, None]
    return xairl.Explanation(
        values=v,
        base_values=np.zeros((40, 3)),
        outputs=v.sum(axis=1),
        states=rng.normal(size=(40, n_features)),
        feature_names=names,
        action_names=["a", "b", "c"],
        method="test",
    )


@pytest.fixture(scope="module")
def image_exp():
    import torch

    torch.manual_seed(0)
    net = torch.nn.Sequential(
        torch.nn.Conv2d(4, 4, 8, 4), torch.nn.ReLU(), torch.nn.Flatten(), torch.nn.Linear(4 * 15 * 15, 6)
    )
    policy = xairl.Policy(
        net.eval(), observation=(4, 64, 64), action_names=["noop", "fire", "up", "right", "left", "down"]
    )
    frames = np.random.default_rng(0).uniform(0, 1, (8, 4, 64, 64)).astype(np.float32)
    return xairl.explain(policy, frames[:3], background=frames[3:])


@pytest.mark.slow
@pytest.mark.parametrize("panels", [1, 2])
def test_region_beeswarm_is_no_thin_strip_and_its_labels_neither_overlap_nor_leave_the_figure(panels, image_exp):
    for exp in (_long_regions(), image_exp):
        fig = plots.beeswarm(exp if panels == 1 else [("simulated", exp), ("real", exp)])
        r = _renderer(fig)
        plotted = fig.axes[:panels]
        for ax in plotted:
            assert ax.get_window_extent(r).width / fig.dpi >= 4.0, "the plot is a thin strip"
            drawn = _tick_labels(ax)
            for ticks in (
                [t for t in drawn if t in ax.get_xticklabels()],
                [t for t in drawn if t in ax.get_yticklabels()],
            ):
                boxes = _boxes(ticks, r)
                for (ta, a), (tb, b) in itertools.pairwise(boxes):
                    assert not _overlap(a, b), f"tick labels {ta!r} and {tb!r} overlap"
        for text, box in _boxes(_all_texts(fig), r):
            assert _inside(box, fig.bbox), f"{text!r} is cut at the figure's edge"


def _texts(fig) -> str:
    return " ".join(" ".join(t.get_text().split()) for t in _all_texts(fig))  # a label wrapped is one label


@pytest.mark.slow
def test_every_figure_names_its_view_margin_by_default(toy, image_exp):
    _, exp = toy
    for make in (plots.beeswarm, plots.importance, plots.waterfall, plots.timeline):
        assert MARGIN in _texts(make(exp)), make.__name__
        assert SCORE in _texts(make(exp, view="score")) and MARGIN not in _texts(make(exp, view="score")), make.__name__
    assert MARGIN in _texts(plots.image(image_exp, 0))
    assert "contribution to each action's score" in _texts(plots.image(image_exp, 0, view="score"))
    # the margin map is the margin's contributions (chosen minus runner-up), summed over the channels
    fig = plots.image(image_exp, 1)
    shown = fig.axes[1].get_images()[-1].get_array()
    assert np.allclose(shown, image_exp.margin()[1].reshape(4, 64, 64).sum(axis=0))


def test_the_reports_figures_and_table_are_in_the_margin_view_and_say_so(toy, tmp_path):
    from xairl.outputs.report import _figures, importance_table

    policy, exp = toy
    figures = _figures([("sampled", exp), ("again", exp)], 3, {"motion": ("speed", "distance")}, tmp_path, policy)
    assert len(figures) == 4
    for caption, path in figures:
        assert "margin over the runner-up" in caption and "score" not in caption, caption
        assert path.read_bytes()[:4] == b"\x89PNG"
    title, table = importance_table([("sampled", exp), ("again", exp)])
    assert "margin over the runner-up" in title and "margin over the runner-up" in table
    ranked = np.abs(exp.margin()).mean(axis=0).argsort()[::-1]
    assert table.index(exp.feature_names[ranked[0]]) < table.index(exp.feature_names[ranked[1]])


def test_the_reports_region_table_gives_each_grid_name_its_pixels(image_exp):
    """Short region names in words, the rows and columns they cover in the table (issue 51, item 13)."""
    from xairl.outputs.report import REGIONS_ARE, TOP_REGIONS, importance_table
    from xairl.policies.regions import in_regions

    regions = in_regions(image_exp)
    title, table = importance_table([("frames", regions)], TOP_REGIONS, REGIONS_ARE)
    assert "<th>pixels</th>" in table and f"The {TOP_REGIONS} most important of" in title
    extents = regions.extras["regions"]
    top = np.abs(regions.margin()).mean(axis=0).argmax()
    name = regions.feature_names[top]
    assert f"<td>{name}</td><td>{extents[name]}</td><td>1</td>" in table
    assert "rows" in extents[name] and "rows" not in name  # the name short, the extent in the table


# --- item 18: no 'IProgress not found' in a notebook --------------------------------------------------------------

NOTEBOOK = (
    "import sys, types\n"
    "sys.modules['ipykernel.zmqshell'] = types.ModuleType('ipykernel.zmqshell')  # what tqdm reads as Jupyter\n"
    "import IPython\n"
)


def _in_a_notebook(code: str) -> subprocess.CompletedProcess:
    """``code`` run where tqdm believes it is in a Jupyter kernel without ipywidgets (as a bare Jupyter install)."""
    return subprocess.run(
        [sys.executable, "-c", NOTEBOOK + code], capture_output=True, text=True, timeout=120, check=False
    )


def test_the_notebook_check_is_real():
    """Without care, tqdm.auto warns 'IProgress not found' here (what shap and transformers import)."""
    run = _in_a_notebook("import tqdm.auto")
    assert run.returncode == 0 and "IProgress not found" in run.stderr


def test_progress_bars_are_quiet_in_a_notebook_and_still_count():
    run = _in_a_notebook(
        "from xairl.explanations.display import progress\n"
        "assert sum(progress(range(3), desc='explaining')) == 3\n"
        "import tqdm.auto  # as shap and transformers do, later\n"
        "print(len(list(progress(range(4), disable=True))))\n"
    )
    assert run.returncode == 0, run.stderr
    assert "IProgress" not in run.stderr and "explaining" in run.stderr and run.stdout.strip() == "4"


@pytest.mark.slow
def test_a_report_in_a_notebook_leaves_tqdm_auto_quiet_for_the_libraries_after_it(tmp_path):
    """The report's bars are the notebook-safe ones: tqdm.auto is then imported quietly, and shap or transformers
    importing it later in the same kernel print nothing."""
    run = _in_a_notebook(
        "from xairl.outputs.report import ReportContent, ReportRequest, write_report\n"
        "from xairl.toy import toy_policy\n"
        "p = toy_policy()\n"
        f"write_report(ReportRequest(out={str(tmp_path)!r}, narrate=False), ReportContent('toy', p, p.background(30),"
        " [('sampled', p.background(8, seed=1))]))\n"
        "import tqdm.auto\n"
    )
    assert run.returncode == 0, run.stderr
    assert "IProgress" not in run.stderr and "explaining (deep_shap)" in run.stderr


@pytest.mark.slow
def test_kernel_shap_shows_no_iprogress_warning_in_a_notebook():
    run = _in_a_notebook(
        "import xairl\n"
        "p = xairl.get_policy('toy')\n"
        "xairl.explain(p, p.background(2, seed=1), background=p.background(10, seed=2),"
        " method='kernel_shap', options={'nsamples': 30})\n"
    )
    assert run.returncode == 0, run.stderr
    assert "IProgress" not in run.stderr
