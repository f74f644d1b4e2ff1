"""The reports in a real browser: index.html, a case report and a study report, written by the
quick runs of this session (the HTML is not committed), opened in headless Chromium (Debian's
package, driven by Playwright), rendered, every link resolving to a file that exists and no
image broken. Screenshots go to the test's temporary folder.

Where Chromium or Playwright is missing the tests skip and say how to install them; `.ci/run`
installs Chromium first, so CI never skips them."""
import shutil
from pathlib import Path
from urllib.parse import unquote, urlparse

import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
# as root, without a sandbox; no background connections (this machine's network is closed)
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]

sync_api = pytest.importorskip(
    "playwright.sync_api", reason="Playwright is missing: pip install -e '.[test]'")
pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="Chromium is missing: apt-get install chromium (Debian's package; "
                             ".ci/run installs it)")


@pytest.fixture(scope="module")
def browser():
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=FLAGS)
        yield b
        b.close()


def _open(browser, page_path, shot):
    """The page loaded from disk: its title, text, links and images, and a screenshot."""
    page = browser.new_page(viewport={"width": 1200, "height": 900})
    errors = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.goto(page_path.as_uri(), wait_until="load")
    found = page.evaluate("""() => ({
        title: document.title,
        text: document.body.innerText.length,
        links: Array.from(document.querySelectorAll('a[href]')).map(a => a.href),
        images: Array.from(document.images).map(i => ({
            alt: i.alt, ok: i.complete && i.naturalWidth > 0}))})""")
    page.screenshot(path=str(shot), full_page=True)
    page.close()
    return found, errors


def _target(url):
    """The file a file:// link points to (its #fragment dropped)."""
    parsed = urlparse(url)
    return Path(unquote(parsed.path)) if parsed.scheme == "file" else None


@pytest.fixture(scope="module")
def reports(library, quick_artefact, quick_truthcube, tmp_path_factory):
    """A reports folder as `pbcm report --quick` writes it: the quick cases, the quick
    artefact and truth-cube studies, the index and the glossary."""
    from cases.reporting.index import write_index
    from cases.registry import CASES
    root = tmp_path_factory.mktemp("reports")
    for name in CASES:
        (root / name).symlink_to((library / name).resolve(), target_is_directory=True)
    (root / "artefact").symlink_to(quick_artefact, target_is_directory=True)
    (root / "truth-cube").symlink_to(quick_truthcube, target_is_directory=True)
    write_index(root, list(CASES), ["artefact", "truth-cube"])
    return root


@pytest.mark.parametrize("page", ["index.html", "paper-cube/report.html",
                                  "artefact/report.html", "truth-cube/report.html",
                                  "glossary.html"])
def test_a_report_page_renders_with_every_link_and_image_whole(browser, reports, page,
                                                               tmp_path):
    """Each report page (the index, a case report, the two study reports, the glossary) renders in
    headless Chromium with no script error, a pbcm title, over 500 characters of text and a drawn
    screenshot; every link resolves to an existing local file, none points outside, and no image
    is broken. The index has at least 10 links, and every page but the index and glossary an
    image."""
    shot = tmp_path / (page.replace("/", "_") + ".png")
    found, errors = _open(browser, reports / page, shot)
    assert errors == []
    assert found["title"].startswith("pbcm") and found["text"] > 500
    assert shot.stat().st_size > 10_000        # something was drawn
    missing = [u for u in found["links"] if _target(u) is not None and not _target(u).exists()]
    assert missing == [], f"links to files that do not exist: {missing}"
    external = [u for u in found["links"] if _target(u) is None]
    assert external == [], f"a report must not point outside the repository: {external}"
    broken = [i["alt"] for i in found["images"] if not i["ok"]]
    assert broken == [], f"broken images: {broken}"
    if page == "index.html":      # every case's report, the artefact study, the glossary
        assert len(found["links"]) >= 10
    if page != "glossary.html":
        assert found["images"] or page == "index.html"


def test_a_broken_image_and_a_dead_link_are_caught(browser, tmp_path):
    """The check itself fails where it must."""
    bad = tmp_path / "bad.html"
    bad.write_text("<html><head><title>pbcm bad</title></head><body>"
                   "<a href='nowhere.html'>x</a><img alt='gone' src='gone.png'></body></html>")
    found, _ = _open(browser, bad, tmp_path / "bad.png")
    assert [i["alt"] for i in found["images"] if not i["ok"]] == ["gone"]
    assert not _target(found["links"][0]).exists()
