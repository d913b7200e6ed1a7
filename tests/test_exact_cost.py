"""exact states its cost before it runs and refuses above max_evaluations; exact and kernel_shap show progress only
when asked (or on a terminal)."""

import numpy as np
import pytest
import torch

import xairl
from tests.conftest import mlp, run
from tests.test_references import brute_force_shapley
from xairl.attributors.exact import MAX_EVALUATIONS, Exact
from xairl.errors import InputError, UnsupportedModelError

SIGNALS, STEPS = 4, 4
NAMES = [f"s{j}_t{t}" for t in range(STEPS) for j in range(SIGNALS)]  # time-major, as observation=(4, 4) flattens


class Counting(torch.nn.Module):
    """The user's module, counting the forward passes and rows it is asked for."""

    def __init__(self, inner: torch.nn.Module):
        super().__init__()
        self.inner = inner
        self.reset()

    def reset(self) -> None:
        self.calls, self.rows, self.largest = 0, 0, 0

    def forward(self, x):
        self.calls += 1
        self.rows += len(x)
        self.largest = max(self.largest, len(x))
        return self.inner(x)


class GruQ(torch.nn.Module):
    """A CleanRL-style GRU Q-network over the last 4 observations of 4 signals: (batch, 4, 4) -> (batch, 3)."""

    def __init__(self):
        super().__init__()
        torch.manual_seed(0)
        self.gru = torch.nn.GRU(SIGNALS, 8, batch_first=True)
        self.head = torch.nn.Linear(8, 3)

    def forward(self, x):
        return self.head(self.gru(x)[0][:, -1])


def counted(inner, f, a=3, **kw):
    module = Counting(inner.eval())
    policy = xairl.Policy(module, feature_names=kw.pop("names", [f"f{i}" for i in range(f)]), **kw)
    module.reset()  # Policy runs the module once to count its outputs
    assert policy.n_actions == a
    return module, policy


def test_exact_refuses_a_16_feature_gru_before_any_forward_pass():
    module, policy = counted(GruQ(), 16, names=NAMES, observation=(STEPS, SIGNALS))
    r = np.random.default_rng(0)
    x, bg = r.normal(size=(3, 16)), r.normal(size=(100, 16))  # the case: 3 states, 100 background rows
    with pytest.raises(InputError) as err:
        xairl.explain(policy, x, background=bg, method="exact")
    msg = str(err.value)
    assert "\n" not in msg
    assert "19,660,800 network evaluations" in msg and "3 states x 2^16 coalitions x 100 background rows" in msg
    assert f"over max_evaluations={MAX_EVALUATIONS:,}" in msg and "'max_evaluations': 19660800" in msg
    assert " MB" in msg  # the memory of its batches, stated too
    assert module.calls == 0


def test_exact_over_16_features_refused_before_any_forward_pass():
    module, policy = counted(mlp([17, 4, 3]), 17)
    with pytest.raises(InputError, match="17 features.*16"):
        xairl.explain(policy, np.zeros((1, 17)), background=np.ones((2, 17)), method="exact")
    assert module.calls == 0


@pytest.mark.slow
@pytest.mark.parametrize("max_rows", [8_192, 20, 3])  # whole table at once; 2 coalitions a batch; a coalition split
def test_exact_with_the_limit_raised_equals_brute_force_and_costs_what_it_said(max_rows):
    module, policy = counted(mlp([5, 16, 16, 3], seed=3), 5)
    r = np.random.default_rng(4)
    x, bg = r.normal(size=(3, 5)).astype(np.float32), r.normal(size=(7, 5)).astype(np.float32)
    cost = Exact({"max_rows": max_rows}).cost(policy, 3, 7)
    assert cost.evaluations == 3 * 2**5 * 7
    with pytest.raises(InputError, match="max_evaluations"):
        xairl.explain(policy, x, bg, "exact", {"max_rows": max_rows, "max_evaluations": cost.evaluations - 1})
    assert module.calls == 0
    exp = xairl.explain(policy, x, bg, "exact", {"max_rows": max_rows, "max_evaluations": cost.evaluations})
    assert module.rows == cost.evaluations + 3  # every row it said, and the states' outputs every method runs
    assert module.largest == min(max(cost.rows_per_forward, 3), max_rows)
    for i in range(3):
        ref = brute_force_shapley(policy.scores, x[i], bg)
        np.testing.assert_allclose(exp.values[i], ref, rtol=0, atol=2e-6)
    np.testing.assert_allclose(exp.base_values[0], policy.scores(bg).mean(axis=0), rtol=0, atol=1e-6)


def test_cost_grows_with_its_parts_and_bounds_the_batches():
    _, policy = counted(GruQ(), 16, names=NAMES, observation=(STEPS, SIGNALS))
    small, big = Exact().cost(policy, 1, 100), Exact({"max_rows": 65_536}).cost(policy, 1, 100)
    assert small.evaluations == big.evaluations == 2**16 * 100
    assert small.rows_per_forward == 8_100 and big.rows_per_forward == 65_500  # whole coalitions of 100 rows
    assert 8_100 * 16 * 4 < small.bytes < big.bytes
    assert Exact().cost(policy, 3, 100).evaluations == 3 * small.evaluations
    assert "6,553,600 network evaluations" in str(small)


def _states(f, n=2, m=6, seed=0):
    r = np.random.default_rng(seed)
    return r.normal(size=(n, f)).astype(np.float32), r.normal(size=(m, f)).astype(np.float32)


@pytest.mark.parametrize("method", ["exact", "kernel_shap"])
def test_progress_is_quiet_unless_asked(method, capsys):
    _, policy = counted(mlp([4, 8, 3]), 4)
    x, bg = _states(4)
    xairl.explain(policy, x, background=bg, method=method)  # stderr is captured: not a terminal
    assert capsys.readouterr().err == ""
    xairl.explain(policy, x, background=bg, method=method, options={"progress": False})
    assert capsys.readouterr().err == ""
    xairl.explain(policy, x, background=bg, method=method, options={"progress": True})
    err = capsys.readouterr().err
    assert "100%" in err and "2/2" in err  # a bar over the two states
    if method == "exact":
        assert "exact: 100%" in err and "state/s" in err


def test_exact_one_state_shows_a_bar_over_its_batches(capsys):
    _, policy = counted(mlp([6, 8, 3]), 6)
    x, bg = _states(6, n=1, m=10)
    xairl.explain(policy, x, background=bg, method="exact", options={"progress": True, "max_rows": 100})
    err = capsys.readouterr().err
    assert "7/7" in err and "batch" in err  # 64 coalitions, 10 a batch of 100 rows


def test_cli_names_the_limit(capsys):
    rc, _, err = run(capsys, "explain", "--n", "2", "--method", "exact", "-o", "max_evaluations=10")
    assert rc == 2 and "max_evaluations=10" in err and "network evaluations" in err and err.count("\n") == 1


def test_a_resumed_run_may_change_how_it_is_shown_and_bounded(tmp_path):
    """progress and max_evaluations say how a run is shown or bounded, not what it computes: resume takes them."""
    torch.manual_seed(0)
    policy = xairl.Policy(torch.nn.Linear(4, 2), feature_names=["a", "b", "c", "d"])
    states, bg = np.random.default_rng(0).normal(size=(6, 4)), np.zeros((3, 4))
    out = tmp_path / "run"
    xairl.explain_to_parquet(policy, states, out, bg, method="exact", chunk_size=3, progress=False)
    (out / "explanations.parquet" / "part-000000000003.parquet").unlink()  # as if interrupted
    again = {"progress": False, "max_evaluations": 10**6}
    xairl.explain_to_parquet(policy, states, out, bg, "exact", again, chunk_size=3, resume=True, progress=False)
    with pytest.raises(xairl.InputError, match="another run"):  # another method is another run
        xairl.explain_to_parquet(policy, states, out, bg, "kernel_shap", chunk_size=3, resume=True)


def test_a_refused_stream_leaves_no_run_and_the_sampler_is_not_called(tmp_path):
    calls = []

    def sampler(n, seed):
        calls.append(n)
        return np.zeros((n, 16))

    policy = xairl.Policy(torch.nn.Linear(16, 2), feature_names=[f"f{i}" for i in range(16)])
    sampled = xairl.Policy(policy.module, feature_names=policy.feature_names, background_sampler=sampler)
    with pytest.raises(InputError, match="max_evaluations"):
        xairl.explain(sampled, np.zeros((30, 16)), method="exact")
    assert calls == []  # refused before the sampler ran
    out = tmp_path / "run"
    with pytest.raises(InputError, match="chunk_size"):
        xairl.explain_to_parquet(policy, np.zeros((30, 16)), out, np.zeros((300, 16)), "exact", progress=False)
    assert not (out / "run.json").exists()


def test_a_long_exact_run_shows_progress_unasked(monkeypatch, capsys):
    """Was: exact on 16 slots ran 6 minutes with nothing printed. Unasked (progress=None), a run past a few seconds
    shows a bar on a terminal, and a plain line every 10 s when stderr is a log or a pipe (here the clock is made
    short instead of the run long)."""
    from xairl.explanations import display

    _, policy = counted(mlp([6, 8, 3]), 6)
    x, bg = _states(6, n=1, m=10)
    options = {"max_rows": 100}  # 7 batches of coalitions
    xairl.explain(policy, x, background=bg, method="exact", options=options)
    assert capsys.readouterr().err == ""  # quick: silent
    monkeypatch.setattr(display, "LINE_EVERY_S", 0.0)
    xairl.explain(policy, x, background=bg, method="exact", options=options)
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 7 and lines[-1].startswith("exact: 100% (7 of 7 batches), ") and "s left" in lines[0]
    x2, bg2 = _states(6, n=2, m=10)
    xairl.explain(policy, x2, background=bg2, method="exact", options=options)
    assert "exact: 50% (1 of 2 states)" in capsys.readouterr().err  # a state's batches move the line too
    monkeypatch.setattr(display, "show_progress", lambda show: True)  # stderr a terminal
    monkeypatch.setattr(display, "QUIET_S", 0.0)
    xairl.explain(policy, x, background=bg, method="exact", options=options)
    err = capsys.readouterr().err
    assert "exact: 100%" in err and "7/7" in err and "exact: 100% (" not in err  # the bar, no plain line


@pytest.mark.parametrize("n_states, n_background", [(-3, 100), (1.5, 100), (2, 0), (True, 10), (2, "100")])
def test_a_cost_of_counts_that_are_no_counts_is_refused(n_states, n_background):
    """Was: Exact().cost(policy, -3, 100) returned a negative number of evaluations, 1.5 states a fraction."""
    _, policy = counted(mlp([4, 8, 3]), 4)
    with pytest.raises(InputError, match="whole number of rows, at least 1"):
        Exact().cost(policy, n_states, n_background)


@pytest.mark.parametrize("options", [{"max_evaluations": True}, {"max_evaluations": 2.5}, {"max_rows": False}])
def test_exact_options_are_whole_numbers_not_bools(options):
    """Was: max_evaluations: True read as 1 (and refused every run with a limit nobody set). A whole number written
    as a float, a numpy integer or '2e7' on the command line is still a count."""
    with pytest.raises(InputError, match="a count is a whole number"):
        Exact(options)
    for count in (10**9, 1e9, np.int64(10**9), "1e9"):
        assert Exact({"max_evaluations": count}).options.max_evaluations == 10**9


def test_exact_is_recommended_first_where_it_is_cheaper_than_kernel_shap():
    """Was: a GRU over a small window was pointed to integrated_gradients or kernel_shap first, where exact gave the
    true values 4.3x faster (2^F coalitions <= kernel_shap's 2F + 2048 samples up to 11 features)."""

    class SmallGru(torch.nn.Module):
        def __init__(self, k):
            super().__init__()
            self.gru, self.head = torch.nn.GRU(k, 4, batch_first=True), torch.nn.Linear(4, 2)

        def forward(self, x):
            return self.head(self.gru(x)[0][:, -1])

    for steps, signals, first in ((3, 3, "exact"), (4, 4, "integrated_gradients")):
        names = [f"s{j}" for j in range(signals)]
        policy = xairl.Policy(SmallGru(signals), feature_names=names, window=steps)
        with pytest.raises(UnsupportedModelError) as err:
            xairl.explain(policy, np.zeros((1, steps, signals)), background=np.ones((2, steps, signals)))
        assert str(err.value).split("use method=")[1].startswith(f"'{first}'"), str(err.value)
        assert ("exact: true Shapley values" in str(err.value)) == (first == "exact")
