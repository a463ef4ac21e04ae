"""Headless Chromium driven over the DevTools protocol through a pipe
(--remote-debugging-pipe: JSON messages separated by NUL bytes on file descriptors 3 and
4), standard library only. Enough to open pages (tabs), evaluate JavaScript in them,
click, take screenshots and close them, as a person would with a browser.
"""
import base64
import fcntl
import json
import os
import select
import shutil
import subprocess
import tempfile
import time

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-dev-shm-usage", "--remote-debugging-pipe", "--window-size=1280,1000",
         "--hide-scrollbars", "--mute-audio"]


def find_chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        p = shutil.which(name)
        if p:
            return p
    return None


class Chrome:
    def __init__(self, binary=None, timeout=30.0):
        self.binary = binary or find_chromium()
        if not self.binary:
            raise RuntimeError("chromium not found (Debian: apt-get install chromium)")
        self.profile = tempfile.mkdtemp(prefix="lagsim-chromium-")
        to_chrome_r, self._w = os.pipe()
        self._r, from_chrome_w = os.pipe()
        # the child's ends above 9 first, so that putting them on 3 and 4 clobbers nothing
        hi_r = fcntl.fcntl(to_chrome_r, fcntl.F_DUPFD, 10)
        hi_w = fcntl.fcntl(from_chrome_w, fcntl.F_DUPFD, 10)
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        to_chrome_r, from_chrome_w = hi_r, hi_w

        def child_fds():   # runs in the child before it closes other descriptors
            os.dup2(to_chrome_r, 3)
            os.dup2(from_chrome_w, 4)

        self.log = open(os.path.join(self.profile, "chromium.log"), "wb")
        self.proc = subprocess.Popen([self.binary, *FLAGS, "--user-data-dir=" + self.profile,
                                      "about:blank"],
                                     stdin=subprocess.DEVNULL, stdout=self.log, stderr=self.log,
                                     preexec_fn=child_fds, pass_fds=(3, 4))
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        self.timeout = timeout
        self.next_id = 0
        self.buf = b""
        self.events = []

    def _read_message(self, deadline):
        while b"\0" not in self.buf:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError("no answer from chromium")
            r, _, _ = select.select([self._r], [], [], left)
            if r:
                chunk = os.read(self._r, 1 << 20)
                if not chunk:
                    raise RuntimeError("chromium closed the pipe (see %s/chromium.log)" % self.profile)
                self.buf += chunk
        msg, self.buf = self.buf.split(b"\0", 1)
        return json.loads(msg)

    def send(self, method, params=None, session=None):
        self.next_id += 1
        m = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            m["sessionId"] = session
        os.write(self._w, json.dumps(m).encode() + b"\0")
        deadline = time.monotonic() + self.timeout
        while True:
            r = self._read_message(deadline)
            if r.get("id") == self.next_id:
                if "error" in r:
                    raise RuntimeError("%s: %s" % (method, r["error"]))
                return r.get("result", {})
            self.events.append(r)

    def open(self, url):
        """A new tab at url; returns (target_id, session_id) once it has loaded."""
        tid = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        sid = self.send("Target.attachToTarget", {"targetId": tid, "flatten": True})["sessionId"]
        self.send("Page.enable", session=sid)
        self.send("Runtime.enable", session=sid)
        self.send("Page.navigate", {"url": url}, session=sid)
        deadline = time.monotonic() + self.timeout
        while time.monotonic() < deadline:
            if self.eval(sid, "document.readyState") == "complete":
                return tid, sid
            time.sleep(0.05)
        raise TimeoutError("page did not load: " + url)

    def front(self, sid):
        """Makes the tab the visible one (a hidden tab gets no animation frames)."""
        self.send("Page.bringToFront", session=sid)

    def eval(self, sid, expression):
        r = self.send("Runtime.evaluate", {"expression": expression, "returnByValue": True,
                                           "awaitPromise": True}, session=sid)
        if "exceptionDetails" in r:
            raise RuntimeError("JavaScript: %s" % r["exceptionDetails"].get("text", r["exceptionDetails"]))
        return r.get("result", {}).get("value")

    def wait_for(self, sid, expression, timeout=10.0, what=None):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            v = self.eval(sid, expression)
            if v:
                return v
            time.sleep(0.05)
        raise TimeoutError("waited %.0f s for %s" % (timeout, what or expression))

    def screenshot(self, sid, path):
        data = self.send("Page.captureScreenshot", {"format": "png"}, session=sid)["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))

    def close_tab(self, tid):
        self.send("Target.closeTarget", {"targetId": tid})

    def quit(self):
        try:
            self.send("Browser.close")
        except Exception:
            pass
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self._r)
        os.close(self._w)
        self.log.close()
        shutil.rmtree(self.profile, ignore_errors=True)
