"""Headless Chromium for the tests: open an HTML page, screenshot it, and measure whether its
math was really typeset (MathML laid out in two dimensions) rather than shown as raw TeX.

Import from a test module as ``from support.browser import ...`` (see :mod:`support`).
Selenium and Pillow are imported only when a browser is started, so this module imports (and
its doctests run) without them.

The browser and its driver are the system's (Debian packages ``chromium`` and
``chromium-driver``, installed by ``.ci/run``), named by absolute path so that Selenium Manager
never looks for, let alone downloads, anything. Host names resolve to nothing inside the
browser: a page that asks for a network resource gets an error, and the report lists the URL.

>>> from support.browser import count_ink_bands
>>> count_ink_bands([0, 3, 5, 0, 0, 0, 4, 0])  # dark pixels per image row, top to bottom
2
"""

from __future__ import annotations

import base64
import contextlib
import io
import os
import re
import tempfile
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from .extras import install_hint

CHROMIUM = Path("/usr/bin/chromium")
CHROMEDRIVER = Path("/usr/bin/chromedriver")

#: Command-line switches: headless, reproducible, and quiet on the network.
CHROMIUM_ARGUMENTS = (
    "--headless=new",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-dev-shm-usage",
    "--hide-scrollbars",
    "--force-device-scale-factor=1",
    "--lang=en-US",
    # No DNS: a page that needs the network fails to load the resource instead of hanging on it.
    "--host-resolver-rules=MAP * ~NOTFOUND",
)

#: Strings that only appear in a page's visible text when TeX was left unconverted.
RAW_TEX_MARKERS = ("\\frac", "\\begin", "\\dot", "\\left", "^{", "_{", "\\\\")
_TEX_COMMAND = re.compile(r"\\[A-Za-z]+")

#: Elements whose screenshot crop must show one band of ink per matrix row (at least 2).
BLOCK_MATRICES = 'math[display="block"]:has(mtable)'

#: A pixel is ink when its grey level (0 black, 255 white) is below this.
INK_THRESHOLD = 160


def chromium_available() -> str | None:
    """Why the browser tests cannot run here, or None when they can."""
    for path, package in ((CHROMIUM, "chromium"), (CHROMEDRIVER, "chromium-driver")):
        if not os.access(path, os.X_OK):
            return (f"{path} not found (install the Debian package {package}: "
                    f"apt-get install --no-install-recommends chromium chromium-driver)")
    for module in ("selenium", "PIL"):
        try:
            __import__(module)
        except ImportError:
            return f"{module} is not installed ({install_hint(module)})"
    return None


@contextlib.contextmanager
def headless_chromium(width: int = 1200, height: int = 900) -> Iterator:
    """A Selenium WebDriver for a fresh headless Chromium whose pages get a ``width`` × ``height``
    CSS-pixel viewport at device pixel ratio 1; the browser is quit, and its temporary profile
    removed, on exit.

    The browser logs every request the page makes (read back by :func:`math_rendering_report`)
    and the page's console messages.
    """
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    with tempfile.TemporaryDirectory(prefix="eomgen-chromium-") as profile:
        options = webdriver.ChromeOptions()
        options.binary_location = str(CHROMIUM)
        for argument in CHROMIUM_ARGUMENTS:
            options.add_argument(argument)
        options.add_argument(f"--user-data-dir={profile}")
        options.add_argument(f"--window-size={width},{height}")
        options.set_capability("goog:loggingPrefs", {"performance": "ALL", "browser": "ALL"})
        service = Service(str(CHROMEDRIVER), log_output=os.devnull)
        driver = webdriver.Chrome(service=service, options=options)
        try:
            # The window holds emulated browser controls; make the page's viewport the size asked.
            driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride", {
                "width": width, "height": height, "deviceScaleFactor": 1, "mobile": False})
            driver.set_page_load_timeout(30)
            driver.set_script_timeout(30)
            yield driver
        finally:
            driver.quit()


@dataclass(frozen=True)
class MathRendering:
    """What the browser made of a page's math.

    Boxes are ``(x, y, width, height)`` in CSS pixels from the page's top-left corner.
    """

    url: str
    screenshot: Path
    #: ``<math>`` elements, and those with ``display="block"``.
    math_count: int
    block_math_count: int
    math_boxes: tuple[tuple[float, float, float, float], ...]
    #: ``document.body.innerText``: what a reader sees as text.
    text: str
    #: Raw TeX found in ``text``: the :data:`RAW_TEX_MARKERS` and any ``\\command``.
    raw_tex: tuple[str, ...]
    #: For each ``<mfrac>``: numerator laid out above the denominator.
    fractions_stacked: tuple[bool, ...]
    #: For each ``<mtable>`` (``<mtr>`` children): every row below the one before it.
    tables_stacked: tuple[bool, ...]
    #: For each :data:`BLOCK_MATRICES` element: bands of ink rows in the screenshot crop.
    ink_bands: tuple[int, ...]
    #: http(s) URLs the page requested (resource timing and the browser's network log).
    external_requests: tuple[str, ...]
    #: Console messages of level SEVERE (failed loads, script errors).
    console_errors: tuple[str, ...]

    @property
    def problems(self) -> list[str]:
        """Every reason to think the math is not typeset, or the page not self-contained."""
        found = []
        if self.raw_tex:
            found.append(f"raw TeX in the visible text: {', '.join(self.raw_tex)}")
        empty = [box for box in self.math_boxes if box[2] <= 0 or box[3] <= 0]
        if empty:
            found.append(f"{len(empty)} of {self.math_count} <math> elements have no size")
        if not all(self.fractions_stacked):
            found.append(f"{self.fractions_stacked.count(False)} of "
                         f"{len(self.fractions_stacked)} <mfrac> not stacked")
        if not all(self.tables_stacked):
            found.append(f"{self.tables_stacked.count(False)} of {len(self.tables_stacked)} "
                         f"<mtable> rows not stacked")
        flat = [bands for bands in self.ink_bands if bands < 2]
        if flat:
            found.append(f"{len(flat)} of {len(self.ink_bands)} displayed matrices show "
                         f"fewer than 2 bands of ink (ink bands: {list(self.ink_bands)})")
        if self.external_requests:
            found.append(f"network resources requested: {', '.join(self.external_requests)}")
        return found

    @property
    def rendered(self) -> bool:
        """True when the page has math and nothing in :attr:`problems`."""
        return self.math_count > 0 and not self.problems


def count_ink_bands(ink_per_row: Sequence[int], min_gap: int = 2) -> int:
    """Number of runs of inked rows, runs separated by at least ``min_gap`` blank rows.

    ``ink_per_row``: (height,) count of dark pixels in each image row, top to bottom.
    """
    bands, blank, inside = 0, min_gap, False
    for ink in ink_per_row:
        if ink:
            if not inside and blank >= min_gap:
                bands += 1
            inside, blank = True, 0
        else:
            inside, blank = False, blank + 1
    return bands


_MEASURE = """
const box = (el) => {
  const r = el.getBoundingClientRect();
  return [r.left + window.scrollX, r.top + window.scrollY, r.width, r.height];
};
const maths = [...document.querySelectorAll('math')];
const fractions = [...document.querySelectorAll('mfrac')].map((f) => {
  if (f.children.length !== 2) return false;
  const num = f.children[0].getBoundingClientRect();
  const den = f.children[1].getBoundingClientRect();
  return num.height > 0 && den.height > 0 && num.bottom <= den.top + 1
         && (num.top + num.bottom) < (den.top + den.bottom);
});
const tables = [...document.querySelectorAll('mtable')].map((t) => {
  const rows = [...t.children].filter((c) => c.localName === 'mtr')
                              .map((r) => r.getBoundingClientRect());
  return rows.length > 0 && rows.every((r, i) => r.height > 0
         && (i === 0 || (r.top > rows[i - 1].top && r.top >= rows[i - 1].bottom - 1)));
});
// Crop: the element, narrowed to its table's columns (stretchy fences would join the rows).
const crops = [...document.querySelectorAll(arguments[0])].map((el) => {
  const [x, y, w, h] = box(el);
  const table = el.querySelector('mtable');
  if (!table) return [x, y, w, h];
  const [tx, , tw] = box(table);
  return [tx, y, tw, h];
});
const resources = performance.getEntriesByType('resource').map((e) => e.name);
return {
  math: maths.map(box),
  block: maths.filter((m) => m.getAttribute('display') === 'block').length,
  text: document.body ? document.body.innerText : '',
  fractions, tables, crops, resources,
  size: [document.documentElement.scrollWidth, document.documentElement.scrollHeight],
};
"""


def math_rendering_report(driver, html_path: Path, screenshot_path: Path,
                          ink_selector: str = BLOCK_MATRICES) -> MathRendering:
    """Open ``html_path`` in ``driver`` (from :func:`headless_chromium`), save a full-page PNG
    screenshot to ``screenshot_path`` and measure the page's math.

    ``ink_selector``: CSS selector of the elements whose screenshot crops are checked for
    stacked rows of ink (:attr:`MathRendering.ink_bands`); an element holding an ``<mtable>``
    is cropped to the table's columns.
    """
    from PIL import Image

    url = Path(html_path).resolve().as_uri()
    driver.get_log("performance")  # drop the previous page's log
    driver.get_log("browser")
    driver.get(url)  # returns after the load event
    driver.execute_async_script(
        "const done = arguments[arguments.length - 1];"
        "document.fonts.ready.then(() => requestAnimationFrame(() => done(true)));")
    measured = driver.execute_script(_MEASURE, ink_selector)

    width, height = measured["size"]
    shot = driver.execute_cdp_cmd("Page.captureScreenshot", {
        "format": "png", "captureBeyondViewport": True, "fromSurface": True,
        "clip": {"x": 0, "y": 0, "width": width, "height": height, "scale": 1}})
    png = base64.b64decode(shot["data"])
    screenshot_path = Path(screenshot_path)
    screenshot_path.parent.mkdir(parents=True, exist_ok=True)
    screenshot_path.write_bytes(png)

    image = Image.open(io.BytesIO(png)).convert("L")
    scale = image.width / width  # device pixels per CSS pixel
    bands = []
    for x, y, w, h in measured["crops"]:
        crop = image.crop((round(x * scale), round(y * scale),
                           round((x + w) * scale), round((y + h) * scale)))
        pixels = crop.load()
        profile = [sum(pixels[i, j] < INK_THRESHOLD for i in range(crop.width))
                   for j in range(crop.height)]
        bands.append(count_ink_bands(profile))

    text = measured["text"]
    raw = [marker for marker in RAW_TEX_MARKERS if marker in text]
    raw += sorted(set(_TEX_COMMAND.findall(text)) - set(raw))
    return MathRendering(
        url=url,
        screenshot=screenshot_path,
        math_count=len(measured["math"]),
        block_math_count=measured["block"],
        math_boxes=tuple(tuple(b) for b in measured["math"]),
        text=text,
        raw_tex=tuple(raw),
        fractions_stacked=tuple(measured["fractions"]),
        tables_stacked=tuple(measured["tables"]),
        ink_bands=tuple(bands),
        external_requests=_external_requests(driver, measured["resources"]),
        console_errors=tuple(entry["message"] for entry in driver.get_log("browser")
                             if entry.get("level") == "SEVERE"),
    )


def _external_requests(driver, resources: Sequence[str]) -> tuple[str, ...]:
    """http(s) URLs among the page's resource-timing entries and the requests in the browser's
    network log (which also holds requests that failed before any timing was recorded)."""
    import json

    urls = list(resources)
    for entry in driver.get_log("performance"):
        message = json.loads(entry["message"])["message"]
        if message.get("method") == "Network.requestWillBeSent":
            urls.append(message["params"]["request"]["url"])
    external = (url for url in urls if url.startswith(("http://", "https://")))
    return tuple(dict.fromkeys(external))


def assert_math_rendered(report: MathRendering, expected_min_math: int = 1) -> None:
    """Fail, saying what is wrong and where the screenshot is, unless the page holds at least
    ``expected_min_math`` typeset ``<math>`` elements, no raw TeX and no network requests."""
    problems = report.problems
    if report.math_count < expected_min_math:
        problems.insert(0, f"{report.math_count} <math> elements, expected at least "
                           f"{expected_min_math}")
    assert not problems, (f"math not rendered in {report.url}:\n  - " + "\n  - ".join(problems)
                          + f"\n  screenshot: {report.screenshot}")
