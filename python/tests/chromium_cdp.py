"""Headless Chromium driven over the DevTools protocol through a pipe (--remote-debugging-pipe):
the browser reads NUL-terminated JSON commands on its fd 3 and writes replies and events on fd 4.
No websocket library and nothing from npm: Debian's chromium and the standard library.

    with Browser() as b:
        page = b.open("file:///.../view.html")     # waits for the load event
        page.evaluate("document.title")
        page.click(120, 80)                        # a real mouse press and release at CSS pixels
        png = page.screenshot()
        page.errors                                # uncaught exceptions, console errors, failed loads
        page.requests                              # every URL the page asked for
"""
import base64
import json
import os
import shutil
import subprocess
import tempfile
import time

CHROMIUM = os.environ.get("OFL_CHROMIUM", "/usr/bin/chromium")
# As the project's other browser test (tests/test_sweep_cli.cpp): no sandbox (root in CI), no GPU,
# nothing that would reach out to the network.
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
         "--disable-sync", "--no-first-run", "--disable-quic", "--disable-extensions", "--mute-audio",
         "--remote-debugging-pipe"]


class Browser:
    def __init__(self, width=1400, height=900, timeout=60):
        self.timeout = timeout
        self.width, self.height = width, height
        self.profile = tempfile.mkdtemp(prefix="ofl_chromium_")
        to_browser_r, self._to_browser = os.pipe()
        self._from_browser, from_browser_w = os.pipe()
        # bash, not sh: dash takes only one-digit descriptors in redirections.
        cmd = ["bash", "-c", f'exec "$@" 3<&{to_browser_r} 4>&{from_browser_w}', "bash", CHROMIUM, *FLAGS,
               f"--user-data-dir={self.profile}", f"--window-size={width},{height}", "about:blank"]
        self.proc = subprocess.Popen(cmd, pass_fds=(to_browser_r, from_browser_w), stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL)
        os.close(to_browser_r)
        os.close(from_browser_w)
        self._buf = b""
        self._next_id = 0
        self.events = []

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        try:
            self.send("Browser.close")
        except Exception:
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        for fd in (self._to_browser, self._from_browser):
            try:
                os.close(fd)
            except OSError:
                pass
        shutil.rmtree(self.profile, ignore_errors=True)

    def _read_message(self, deadline):
        while b"\0" not in self._buf:
            if time.monotonic() > deadline:
                raise TimeoutError("no answer from Chromium")
            chunk = os.read(self._from_browser, 1 << 20)
            if not chunk:
                raise RuntimeError(f"Chromium closed the pipe (exit code {self.proc.poll()})")
            self._buf += chunk
        msg, self._buf = self._buf.split(b"\0", 1)
        return json.loads(msg)

    def send(self, method, params=None, session=None):
        self._next_id += 1
        msg = {"id": self._next_id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self._to_browser, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + self.timeout
        while True:
            m = self._read_message(deadline)
            if m.get("id") == self._next_id:
                if "error" in m:
                    raise RuntimeError(f"{method}: {m['error']}")
                return m.get("result", {})
            self.events.append(m)

    def pump(self, seconds):
        """Reads events for a while (the pipe is only read while waiting for answers otherwise)."""
        end = time.monotonic() + seconds
        self.send("Browser.getVersion")
        while time.monotonic() < end:
            time.sleep(0.05)
            self.send("Browser.getVersion")

    def open(self, url):
        target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        page = Page(self, session, target)
        for domain in ("Page", "Runtime", "Log", "Network"):
            self.send(domain + ".enable", session=session)
        self.send("Emulation.setDeviceMetricsOverride",
                  {"width": self.width, "height": self.height, "deviceScaleFactor": 1, "mobile": False}, session=session)
        page.navigate(url)
        return page


class Page:
    def __init__(self, browser, session, target):
        self.b, self.session, self.target = browser, session, target

    def close(self):
        self.b.send("Target.closeTarget", {"targetId": self.target})

    def _events(self, method=None):
        return [e for e in self.b.events if e.get("sessionId") == self.session and (method is None or e["method"] == method)]

    def navigate(self, url):
        start = len(self.b.events)
        self.b.send("Page.navigate", {"url": url}, session=self.session)
        deadline = time.monotonic() + self.b.timeout
        while not any(e.get("method") == "Page.loadEventFired" and e.get("sessionId") == self.session
                      for e in self.b.events[start:]):
            if time.monotonic() > deadline:
                raise TimeoutError(f"{url} did not load")
            self.b.send("Browser.getVersion")  # reads the events in between
            time.sleep(0.02)

    def evaluate(self, expression):
        r = self.b.send("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True},
                        session=self.session)
        if "exceptionDetails" in r:
            raise RuntimeError(f"{expression}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def mouse(self, kind, x, y, buttons=0, button="none"):
        self.b.send("Input.dispatchMouseEvent", {"type": kind, "x": x, "y": y, "button": button, "buttons": buttons,
                                                 "clickCount": 1 if kind != "mouseMoved" else 0}, session=self.session)

    def click(self, x, y):
        self.mouse("mouseMoved", x, y)
        self.mouse("mousePressed", x, y, 1, "left")
        self.mouse("mouseReleased", x, y, 0, "left")

    def drag(self, x0, y0, x1, y1, steps=5):
        self.mouse("mouseMoved", x0, y0)
        self.mouse("mousePressed", x0, y0, 1, "left")
        for i in range(1, steps + 1):
            self.mouse("mouseMoved", x0 + (x1 - x0) * i / steps, y0 + (y1 - y0) * i / steps, 1, "left")
        self.mouse("mouseReleased", x1, y1, 0, "left")

    def screenshot(self):
        return base64.b64decode(self.b.send("Page.captureScreenshot", {"format": "png"}, session=self.session)["data"])

    @property
    def errors(self):
        out = [e["params"]["exceptionDetails"].get("exception", {}).get("description")
               or e["params"]["exceptionDetails"].get("text") for e in self._events("Runtime.exceptionThrown")]
        out += [" ".join(str(a.get("value", a.get("description", ""))) for a in e["params"]["args"])
                for e in self._events("Runtime.consoleAPICalled") if e["params"]["type"] in ("error", "assert")]
        out += [e["params"]["entry"]["text"] for e in self._events("Log.entryAdded") if e["params"]["entry"]["level"] == "error"]
        out += [f"failed to load {e['params'].get('errorText')}" for e in self._events("Network.loadingFailed")]
        return out

    @property
    def requests(self):
        return [e["params"]["request"]["url"] for e in self._events("Network.requestWillBeSent")]
