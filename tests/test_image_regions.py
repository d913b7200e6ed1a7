"""An image policy is narrated, verified and reported in regions (patches of one channel named in words), not in
pixels; its repr and its explanation's stay short. A small CNN on 3x64x64 frames, built here (no training)."""

import numpy as np
import pytest
import torch

import xairl
from tests.conftest import small_cnn
from tests.work_budget import calls
from xairl.outputs.report import ReportContent, ReportRequest, write_report
from xairl.policies.regions import in_regions

NARRATE_CALLS = 1_000_000  # function calls to narrate one state of the CNN below, verification included

REGION = "patch "


@pytest.fixture(scope="module")
def cnn():
    policy, frames = small_cnn()
    return policy, frames, xairl.explain(policy, frames[:2], background=frames[2:])


def test_an_image_is_narrated_in_verified_regions_with_little_work(cnn):
    """Work counted in function calls (cProfile's count), not seconds (a 2 s limit failed under load): ~270,000 for
    192 regions; in pixels (12,288 features) many times more. The time: benchmarks/bench_test_timings.py."""
    policy, _, exp = cnn
    regions = in_regions(exp)
    assert len(regions.feature_names) == 3 * 8 * 8 and regions.feature_names[0] == "patch A1 of channel 0"
    np.testing.assert_allclose(regions.values.sum(axis=1), exp.values.sum(axis=1), atol=1e-9)  # additivity kept
    xairl.narrate(exp, 0, policy=policy, robustness=False)  # warm: templates, the vocabulary's regexes
    for i in range(2):
        narrative, work = calls(xairl.narrate, exp, i, policy=policy, robustness=False)
        assert work < NARRATE_CALLS
        assert narrative.verified, [c for c in narrative.claims if c.status != "verified"]
        assert REGION in narrative.text and "obs[" not in narrative.text
        assert xairl.verify(narrative.text, exp, i, policy).ok  # the pixel explanation is read in regions too
        region = next(c for c in narrative.claims if c.kind == "feature").text
        assert region in regions.feature_names


def test_a_wrong_region_or_its_number_is_contradicted(cnn):
    policy, _, exp = cnn
    text = xairl.narrate(exp, 0, policy=policy, robustness=False).text
    start = text.index(REGION) + len(REGION)
    shifted = text[:start] + "Z" + text[start + 1 :]  # no patch is in column Z of an 8x8 grid
    check = xairl.verify(shifted, exp, 0, policy)
    assert check.status == "contradicted"
    assert any(c.rule == "region.unknown" and c.status == "contradicted" for c in check.claims)
    channel = text.index(" of channel ", start) + len(" of channel ")  # another region: its numbers are not these
    other = str((int(text[channel]) + 1) % 3)
    assert xairl.verify(text[:channel] + other + text[channel + 1 :], exp, 0, policy).status == "contradicted"


def test_flat_small_and_grouped_explanations_are_narrated_as_before(cnn):
    _, _, exp = cnn
    flat = xairl.Policy(torch.nn.Linear(4, 2), observation=(4,))
    small = xairl.Policy(torch.nn.Sequential(torch.nn.Flatten(), torch.nn.Linear(3 * 8 * 8, 2)), observation=(3, 8, 8))
    rng = np.random.default_rng(1)
    for policy in (flat, small):
        states = rng.normal(size=(8, policy.n_features))
        e = xairl.explain(policy, states[:2], background=states[2:])
        assert in_regions(e) is e  # pixels of an 8x8 image are their own regions
        narrative = xairl.narrate(e, 0, policy=policy, robustness=False)
        assert narrative.verified and "patch" not in narrative.text
    grouped = in_regions(exp)
    assert in_regions(grouped) is grouped


def test_an_image_part_of_a_dict_observation_is_narrated_in_regions():
    class Net(torch.nn.Module):
        def __init__(self):
            super().__init__()
            self.image, self.vec = torch.nn.Conv2d(1, 2, 4, 4), torch.nn.Linear(2, 3)

        def forward(self, obs):
            return self.image(obs["image"]).flatten(1)[:, :3] + self.vec(obs["vec"])

    torch.manual_seed(0)
    policy = xairl.Policy(Net(), observation={"image": (1, 20, 20), "vec": (2,)})
    rng = np.random.default_rng(2)
    states = {"image": rng.normal(size=(8, 1, 20, 20)), "vec": rng.normal(size=(8, 2))}
    exp = xairl.explain(policy, {k: v[:1] for k, v in states.items()}, background={k: v[1:] for k, v in states.items()})
    names = in_regions(exp).feature_names
    assert names[0] == "patch A1 of image" and names[-2:] == ("vec[0]", "vec[1]")
    narrative = xairl.narrate(exp, 0, policy=policy, robustness=False)
    assert narrative.verified, narrative.text


def test_reprs_are_short(cnn):
    policy, _, exp = cnn
    for obj, what in ((policy, "Policy('cnn', "), (exp, "Explanation('deep_shap', 2 states; ")):
        text = repr(obj)
        assert text.startswith(what) and len(text) < 400, text
        assert "12288 features: obs[0,0,0], obs[0,0,1], obs[0,0,2], ..." in text and "obs[2,63,63]" not in text
        assert "4 actions: action_0, action_1, action_2, action_3" in text


def test_the_report_lists_the_top_regions_not_every_pixel(cnn, tmp_path):
    policy, frames, _ = cnn
    content = ReportContent("cnn", policy, frames[6:], [("sim", frames[:3])])
    path = write_report(ReportRequest(tmp_path, n_narrated=2, robustness=False, progress=False, records=False), content)
    page = path.read_text()
    assert "The 20 most important of 192 regions" in page and REGION in page
    assert "obs[" not in page and page.count("verdict: <b>verified</b>") == page.count("<p class='check ") > 0
    assert path.stat().st_size < 600_000  # its figures included; cards listing every pixel made it megabytes
