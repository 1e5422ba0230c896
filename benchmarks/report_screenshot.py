"""The report's first screen in a real browser: screenshot at 1400×900 and what lies on it.

Usage: python benchmarks/report_screenshot.py [report.html] [--out results/benchmarks/report_first_screen.png]

Without a report path, builds the report of the working directory's results (``snakemake --report``, into a
temporary file). Opens it in headless Chromium (``/usr/bin/chromium``, or ``$CHROMIUM``) through the DevTools
protocol on a pipe (``--remote-debugging-pipe``: no extra package), waits until Snakemake's React app has drawn
the Workflow panel, then

* saves a 1400×900 screenshot (``results/benchmarks/report_first_screen.png`` by default);
* measures where the front page's tables lie (``getBoundingClientRect`` of ``#lf-impedance-summary`` ...);
* collects the text drawn inside the first screen.

Prints the tables' boxes and the first screen's text, and exits with status 1 when the impedance summary or the
truth-recovery table does not lie wholly within the first screen, or when the first screen lacks the verdicts.
"""

from __future__ import annotations

import argparse
import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from loper_analysis.layout import RESULTS_DIR

ROOT = Path(__file__).resolve().parents[1]
#: The screen the requirement is written for (CSS pixels).
WIDTH_PX, HEIGHT_PX = 1400, 900
#: Tables of the front page that must lie within the first screen.
FIRST_SCREEN_TABLES = ("lf-impedance-summary", "lf-truth-recovery")
#: Every table of the front page whose box is measured.
TABLES = (
    "lf-impedance-summary",
    "lf-truth-recovery",
    "lf-figure",
    "lf-recorded",
    "lf-trials",
    "lf-transparency",
    "lf-device",
    "lf-run",
)
CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    f"--window-size={WIDTH_PX},{HEIGHT_PX}",
    "--hide-scrollbars",
    "--mute-audio",
)

#: Page script: the boxes of the tables and the text of every text node drawn inside the viewport.
_MEASURE = """(() => {
  const boxes = {};
  for (const id of %s) {
    const el = document.getElementById(id);
    if (el) { const r = el.getBoundingClientRect();
              boxes[id] = {top: r.top, bottom: r.bottom, left: r.left, right: r.right}; }
  }
  const lines = [];
  const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  const range = document.createRange();
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    const text = n.textContent.trim();
    if (!text || n.parentElement.closest('script,style')) continue;
    range.selectNodeContents(n);
    const r = range.getBoundingClientRect();
    if (r.width > 0 && r.height > 0 && r.bottom > 0 && r.top < innerHeight && r.right > 0 && r.left < innerWidth)
      lines.push(text);
  }
  return JSON.stringify({viewport: [innerWidth, innerHeight], boxes: boxes, text: lines.join(' ')});
})()"""


def chromium_path() -> str | None:
    """The Chromium to drive: ``$CHROMIUM``, else ``/usr/bin/chromium`` when it exists."""
    path = os.environ.get("CHROMIUM", "/usr/bin/chromium")
    return path if Path(path).is_file() else None


class DevTools:
    """A minimal DevTools-protocol client on Chromium's pipe (fd 3: commands in, fd 4: replies out, NUL-ended)."""

    def __init__(self, chromium: str, timeout_s: float = 60.0):
        self.timeout_s = timeout_s
        self._profile = tempfile.mkdtemp(prefix="report-screenshot-")
        to_child_r, self._to_child = os.pipe()
        self._from_child, from_child_w = os.pipe()

        def _fds():  # in the child: the pipe ends Chromium expects on fds 3 and 4 (dup first: no clash)
            read_end, write_end = os.dup(to_child_r), os.dup(from_child_w)
            os.dup2(read_end, 3)
            os.dup2(write_end, 4)

        # close_fds=False: subprocess would close fds 3 and 4 after preexec_fn; Python's own descriptors are
        # not inheritable (PEP 446), so nothing else leaks into Chromium
        self._proc = subprocess.Popen(
            [chromium, *CHROMIUM_FLAGS, f"--user-data-dir={self._profile}", "--remote-debugging-pipe", "about:blank"],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            close_fds=False,
            preexec_fn=_fds,
        )
        os.close(to_child_r)
        os.close(from_child_w)
        self._buffer = b""
        self._next_id = 0
        self._session = None
        page = next(t for t in self.call("Target.getTargets")["targetInfos"] if t["type"] == "page")
        self._session = self.call("Target.attachToTarget", targetId=page["targetId"], flatten=True)["sessionId"]

    def call(self, method: str, **params) -> dict:
        """Send one command (to the page once attached) and return its result."""
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params}
        if self._session is not None and not method.startswith("Target."):
            message["sessionId"] = self._session
        os.write(self._to_child, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + self.timeout_s
        while True:
            while b"\0" not in self._buffer:
                if time.monotonic() > deadline:
                    raise TimeoutError(f"Chromium did not answer {method} within {self.timeout_s} s")
                chunk = os.read(self._from_child, 1 << 20)
                if not chunk:
                    raise RuntimeError(f"Chromium closed the pipe during {method}")
                self._buffer += chunk
            raw, self._buffer = self._buffer.split(b"\0", 1)
            reply = json.loads(raw)
            if reply.get("id") == self._next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})

    def evaluate(self, expression: str):
        """The value of a page expression."""
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True)
        if "exceptionDetails" in result:
            raise RuntimeError(f"page script failed: {result['exceptionDetails']}")
        return result["result"].get("value")

    def close(self) -> None:
        try:
            self.call("Browser.close")
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self._proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()
        for fd in (self._to_child, self._from_child):
            try:
                os.close(fd)
            except OSError:
                pass
        shutil.rmtree(self._profile, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def first_screen(
    report_html: Path,
    screenshot_png: Path | None = None,
    chromium: str | None = None,
    wait_s: float = 30.0,
    ready_id: str = "lf-impedance-summary",
) -> dict:
    """Open the report at 1400×900, wait for the front page (its element ``ready_id``), measure it and
    (optionally) save a screenshot.

    Returns ``{"viewport": [w, h], "boxes": {id: {top, bottom, left, right}}, "text": first screen's text,
    "images": [[alt, natural width, natural height], ...] of the front page's figures, "load_s": seconds until
    the front page was drawn}`` (CSS pixels, relative to the viewport).
    """
    chromium = chromium or chromium_path()
    if chromium is None:
        raise FileNotFoundError("no Chromium: set $CHROMIUM or install /usr/bin/chromium")
    with DevTools(chromium) as browser:
        browser.call(
            "Emulation.setDeviceMetricsOverride", width=WIDTH_PX, height=HEIGHT_PX, deviceScaleFactor=1, mobile=False
        )
        start = time.monotonic()
        browser.call("Page.navigate", url=Path(report_html).resolve().as_uri())
        while not browser.evaluate(f"!!document.getElementById('{ready_id}') && document.readyState === 'complete'"):
            if time.monotonic() - start > wait_s:
                raise TimeoutError(f"{report_html}: the front page did not appear within {wait_s} s")
            time.sleep(0.1)
        load_s = time.monotonic() - start
        browser.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
        time.sleep(0.3)  # the rule graph (vega) draws after the first frames
        measured = json.loads(browser.evaluate(_MEASURE % json.dumps(list(TABLES))))
        measured["images"] = browser.evaluate(
            "Array.from(document.querySelectorAll('.lf img')).map(i => [i.alt, i.naturalWidth, i.naturalHeight])"
        )
        if screenshot_png is not None:
            data = base64.b64decode(browser.call("Page.captureScreenshot", format="png")["data"])
            sys.path.insert(0, str(ROOT / "src"))
            from loper_analysis.io.atomic import write_bytes

            write_bytes(screenshot_png, data, "screenshot")
    measured["load_s"] = load_s
    return measured


def problems(measured: dict) -> list[str]:
    """What keeps the first screen from showing the headline results (empty: nothing)."""
    out = []
    width, height = measured["viewport"]
    for table in FIRST_SCREEN_TABLES:
        box = measured["boxes"].get(table)
        if box is None:
            out.append(f"#{table} is not on the page")
        elif box["top"] < 0 or box["bottom"] > height or box["left"] < 0 or box["right"] > width:
            out.append(
                f"#{table} lies at top {box['top']:.0f} … bottom {box['bottom']:.0f} px, left "
                f"{box['left']:.0f} … right {box['right']:.0f} px: not within {width}×{height}"
            )
    for words in ("the truth (", "Impedance: across-subject mean", "Truth recovery"):
        if words not in measured["text"]:
            out.append(f"the first screen does not show {words!r}")
    return out


def build_report(workdir: Path, out_html: Path) -> None:
    """``snakemake --report out_html`` in ``workdir``."""
    res = subprocess.run(
        [sys.executable, "-m", "snakemake", "--report", str(out_html)],
        cwd=workdir,
        capture_output=True,
        text=True,
        timeout=600,
    )
    if res.returncode != 0:
        raise SystemExit(f"snakemake --report failed:\n{res.stderr[-3000:]}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("report", nargs="?", type=Path, help="report.html (default: build it from ./results)")
    parser.add_argument(
        "--out",
        type=Path,
        default=Path(RESULTS_DIR, "benchmarks", "report_first_screen.png"),
        help="screenshot (PNG, 1400×900)",
    )
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        report = args.report
        if report is None:
            report = Path(tmp) / "report.html"
            start = time.monotonic()
            build_report(Path.cwd(), report)
            print(f"report built in {time.monotonic() - start:.1f} s")
        measured = first_screen(report, args.out)
    print(f"front page drawn {measured['load_s']:.1f} s after opening; screenshot: {args.out}")
    for table, box in measured["boxes"].items():
        print(
            f"  #{table:22s} top {box['top']:6.0f}  bottom {box['bottom']:6.0f}  "
            f"left {box['left']:5.0f}  right {box['right']:5.0f} px"
        )
    print(f"first screen's text ({len(measured['text'])} characters):\n  {measured['text'][:1500]}")
    found = problems(measured)
    for p in found:
        print(f"PROBLEM: {p}")
    print("first screen: OK" if not found else "first screen: FAILS")
    return 1 if found else 0


if __name__ == "__main__":
    raise SystemExit(main())
