"""The review page in a real browser (Debian's headless Chromium through its chromedriver): load it, see the
evidence beside each narrative, review items, and find the verdicts in the SQLite store."""
import shutil
import urllib.request

import pytest

import xairl
from xairl.feedback import FeedbackStore
from xairl.review import page, serve_in_thread
from xairl.toy import toy_policy

BROWSER = shutil.which("chromium") and shutil.which("chromedriver")


@pytest.fixture
def store(tmp_path):
    p = toy_policy()
    bg = p.background(50)
    exp = xairl.explain(p, p.background(3, seed=4), background=bg)
    store = FeedbackStore(tmp_path / "fb.sqlite")
    for i in range(2):
        xairl.narrate(exp, i, policy=p, background=bg, robustness=False, store=store)
    return store


def test_page_shows_the_evidence_without_a_browser(store):
    r = store.records()[0]
    assert r.evidence["runner_up"] and len(r.evidence["features"]) == 5 and r.evidence["sentences"]
    html = page(store, "t")
    assert html.count("class=item") == 2 and "class=waterfall" in html and "class=state" in html
    assert "s verified" in html and "margin of" in html and "coverage" in html


def test_a_post_without_the_page_token_is_refused(store):
    server, url = serve_in_thread(store)
    try:
        req = urllib.request.Request(url + "review", data=b"id=1&status=accepted&token=forged", method="POST")
        with pytest.raises(urllib.error.HTTPError, match="403"):
            urllib.request.urlopen(req, timeout=10)
        assert store.records()[0].status == "pending"
    finally:
        server.shutdown()


@pytest.mark.skipif(not BROWSER, reason="Debian's chromium and chromium-driver are not installed (make test installs them)")
def test_review_in_headless_chromium(store, tmp_path):
    from selenium import webdriver
    from selenium.common.exceptions import StaleElementReferenceException
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    def message(driver):
        shown = driver.find_elements(By.CSS_SELECTOR, ".message")
        return shown[0].text if shown else False

    def wait(driver):  # a click posts and the page reloads: an element read during the reload is stale, read again
        return WebDriverWait(driver, 20, ignored_exceptions=(StaleElementReferenceException,))

    opts = webdriver.ChromeOptions()
    opts.binary_location = shutil.which("chromium")
    for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--disable-dev-shm-usage",
                 f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1200,1600"):
        opts.add_argument(flag)
    server, url = serve_in_thread(store)
    driver = webdriver.Chrome(options=opts, service=Service(shutil.which("chromedriver")))
    try:
        driver.get(url)
        items = driver.find_elements(By.CSS_SELECTOR, "section.item")
        assert len(items) == 2
        first, second = (i.get_attribute("id").split("-")[1] for i in items)
        card = driver.find_element(By.ID, f"item-{first}")
        assert card.find_elements(By.CSS_SELECTOR, ".wf-bar") and card.find_elements(By.CSS_SELECTOR, "table.state")
        assert card.find_elements(By.CSS_SELECTOR, "span.s.verified")
        driver.save_screenshot(str(tmp_path / "review.png"))
        card.find_element(By.CSS_SELECTOR, "button.accept").click()
        assert f"#{first} accepted" in wait(driver).until(message)
        card = driver.find_element(By.ID, f"item-{second}")
        card.find_element(By.NAME, "correction").send_keys("The policy turned: the goal was close.")
        card.find_element(By.CSS_SELECTOR, "button.correct").click()
        wait(driver).until(lambda d: f"#{second} corrected" in (message(d) or ""))
        assert "Nothing to review" in driver.page_source
    finally:
        driver.quit()
        server.shutdown()
    got = {r.id: (r.status, r.correction) for r in store.records()}
    assert got == {int(first): ("accepted", None), int(second): ("corrected", "The policy turned: the goal was close.")}
    assert (tmp_path / "review.png").stat().st_size > 10_000
