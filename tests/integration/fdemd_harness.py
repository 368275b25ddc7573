"""Starts the real fdemd on a free loopback port with a temporary data
directory and talks HTTP to it (stdlib only), for the integration tests.

    d = Daemon()            # bin/fdemd, or $FDEMD_BIN
    d.start()
    status, body = d.json("POST", "/cases", tiny_case())
    d.stop()                # SIGTERM, returns the exit code
    d.start()               # same data directory: a restart
    d.close()               # kill if needed, remove the directory
"""
import contextlib
import http.client
import json
import os
import select
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FDEMD_BIN = os.environ.get("FDEMD_BIN", os.path.join(ROOT, "bin", "fdemd"))
if not os.path.isabs(FDEMD_BIN):
    FDEMD_BIN = os.path.join(ROOT, FDEMD_BIN)
FDEMCTL_BIN = os.environ.get("FDEMCTL_BIN", os.path.join(ROOT, "bin", "fdemctl"))
if not os.path.isabs(FDEMCTL_BIN):
    FDEMCTL_BIN = os.path.join(ROOT, FDEMCTL_BIN)
# Sanitizer builds are several times slower; time limits scale with this.
SLOW = 4.0 if "san" in os.path.basename(os.path.dirname(FDEMD_BIN)) else 1.0
TERMINAL = ("finished", "stopped", "failed")


def tiny_case(name="tiny", end=0.001, divisions=(10, 10), interval=None, young=3e10, **extra):
    """A 0.1 m square block (2*nx*ny elements) falling onto a fixed base."""
    case = {
        "name": name,
        "materials": {"rock": {"density": 2700, "young": young, "poisson": 0.25}},
        "parts": [{"name": "block", "material": "rock",
                   "rectangle": {"origin": [0, 0], "size": [0.1, 0.1], "divisions": list(divisions)},
                   "velocity": [0, -1]}],
        "constraints": [{"box": [-1, -0.001, 1, 0.001], "fix": ["x", "y"]}],
        "time": {"end": end},
        "output": {"interval": interval if interval is not None else end / 10,
                   "fields": ["position", "velocity", "stress"]},
    }
    case.update(extra)
    return case


def boom_case(name="boom"):
    """Goes non-finite within a few steps (an absurd force): a failed case."""
    case = tiny_case(name, end=0.01, divisions=(4, 4))
    case["constraints"].append({"box": [0.09, 0.09, 0.2, 0.2], "force": [1e300, 1e300]})
    return case


@contextlib.contextmanager
def fetched_result(daemon, case_id):
    """The case's result.h5 as GET /cases/ID/result.h5 serves it, open in
    h5py (a temporary copy, removed on exit)."""
    import h5py
    status, _, data = daemon.request("GET", "/cases/%s/result.h5" % case_id)
    assert status == 200, data[:200]
    fd, path = tempfile.mkstemp(suffix=".h5")
    with os.fdopen(fd, "wb") as f:
        f.write(data)
    try:
        with h5py.File(path, "r") as f:
            yield f
    finally:
        os.unlink(path)


class Daemon:
    def __init__(self, data_dir=None, token=None, args=(), env=None):
        self.owns_dir = data_dir is None
        self.root = tempfile.mkdtemp(prefix="fdemd-test-") if data_dir is None else None
        self.data_dir = data_dir or os.path.join(self.root, "data")
        self.token = token
        self.args = list(args)
        self.env = env
        self.proc = None
        self.port = None
        self.log_path = os.path.join(self.root or tempfile.gettempdir(), "fdemd.log")
        self.default_token = token

    # ---------------------------------------------------------- process
    def start(self, timeout=10.0):
        env = dict(os.environ)
        env.pop("FDEMD_TOKEN", None)
        if self.env:
            env.update(self.env)
        cmd = [FDEMD_BIN, "--listen", "127.0.0.1:0", "--data", self.data_dir] + self.args
        if self.token:
            cmd += ["--token", self.token]
        self.log = open(self.log_path, "ab")
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=self.log, env=env)
        line = self._first_line(timeout * SLOW)
        prefix = "listening on 127.0.0.1:"
        if not line.startswith(prefix):
            self.kill()
            raise RuntimeError("fdemd did not start: %r\n%s" % (line, self.log_tail()))
        self.port = int(line[len(prefix):])
        return self

    def _first_line(self, timeout):
        deadline = time.monotonic() + timeout
        buf = b""
        fd = self.proc.stdout.fileno()
        while b"\n" not in buf:
            left = deadline - time.monotonic()
            if left <= 0 or self.proc.poll() is not None and not select.select([fd], [], [], 0)[0]:
                break
            if select.select([fd], [], [], left)[0]:
                chunk = os.read(fd, 256)
                if not chunk:
                    break
                buf += chunk
        return buf.decode(errors="replace").strip()

    def stop(self, sig=signal.SIGTERM, timeout=10.0):
        """Sends `sig` and returns (exit code, seconds it took)."""
        started = time.monotonic()
        self.proc.send_signal(sig)
        try:
            code = self.proc.wait(timeout * SLOW)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            code = None
        self._closed()
        return code, time.monotonic() - started

    def kill(self):
        if self.proc and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        self._closed()

    def _closed(self):
        if self.proc and self.proc.stdout:
            self.proc.stdout.close()
        if getattr(self, "log", None):
            self.log.close()
            self.log = None

    def close(self):
        self.kill()
        if self.owns_dir and self.root:
            shutil.rmtree(self.root, ignore_errors=True)

    def log_tail(self, size=4000):
        try:
            with open(self.log_path, "rb") as f:
                return f.read()[-size:].decode(errors="replace")
        except OSError:
            return ""

    # ------------------------------------------------------------- HTTP
    def connection(self, timeout=30.0):
        return http.client.HTTPConnection("127.0.0.1", self.port, timeout=timeout * SLOW)

    def request(self, method, path, body=None, headers=None, token=Ellipsis):
        """Returns (status, headers dict with lower-case names, body bytes)."""
        headers = dict(headers or {})
        token = self.default_token if token is Ellipsis else token
        if token:
            headers["Authorization"] = "Bearer " + token
        if isinstance(body, (dict, list)):
            body = json.dumps(body).encode()
            headers.setdefault("Content-Type", "application/json")
        elif isinstance(body, str):
            body = body.encode()
        if method == "POST" and body is None:
            body = b""
        conn = self.connection()
        try:
            conn.request(method, path, body=body, headers=headers)
            resp = conn.getresponse()
            data = resp.read()
            return resp.status, {k.lower(): v for k, v in resp.getheaders()}, data
        finally:
            conn.close()

    def fdemctl(self, *args, stdin=None, cwd=None, timeout=30):
        """Runs fdemctl against this daemon (FDEMD_URL, its token if it has
        one) and returns the CompletedProcess, text out and err."""
        env = dict(os.environ, FDEMD_URL="http://127.0.0.1:%d" % self.port)
        env.pop("FDEMD_TOKEN", None)
        if self.default_token:
            env["FDEMD_TOKEN"] = self.default_token
        return subprocess.run([FDEMCTL_BIN] + list(args), input=stdin, capture_output=True,
                              text=True, env=env, cwd=cwd, timeout=timeout * SLOW)

    def json(self, method, path, body=None, **kw):
        status, headers, data = self.request(method, path, body, **kw)
        try:
            parsed = json.loads(data) if data else None
        except ValueError:
            parsed = data
        return status, parsed

    # ----------------------------------------------------------- cases
    def create(self, case, start=False):
        status, body = self.json("POST", "/cases" + ("?start=true" if start else ""), case)
        if status != 201:
            raise AssertionError("POST /cases answered %s: %s" % (status, body))
        return body

    def status(self, case_id):
        status, body = self.json("GET", "/cases/" + case_id)
        if status != 200:
            raise AssertionError("GET /cases/%s answered %s: %s" % (case_id, status, body))
        return body

    def wait(self, case_id, predicate, timeout=20.0, what="condition"):
        deadline = time.monotonic() + timeout * SLOW
        while True:
            st = self.status(case_id)
            if predicate(st):
                return st
            if time.monotonic() > deadline:
                raise AssertionError("timed out waiting for %s; last status %s" % (what, st))
            time.sleep(0.02)

    def wait_state(self, case_id, states, timeout=20.0):
        states = (states,) if isinstance(states, str) else tuple(states)
        return self.wait(case_id, lambda s: s["state"] in states, timeout, "state in %s" % (states,))

    def steps_per_second(self):
        """Measures how fast this daemon steps tiny_case(), so tests can size
        'long' cases in seconds of wall time on any machine or build."""
        st = self.create(tiny_case("probe", end=1e3), start=True)
        t0 = time.monotonic()
        first = st["step"]
        time.sleep(0.4)
        now = self.status(st["id"])
        elapsed = time.monotonic() - t0
        self.request("DELETE", "/cases/" + st["id"])
        return max((now["step"] - first) / elapsed, 100.0), now["dt"]

    def case_lasting(self, seconds, name="timed", **kw):
        """tiny_case() whose run takes about `seconds` of wall time here."""
        rate, dt = self.steps_per_second()
        return tiny_case(name, end=rate * seconds * dt, **kw)


class DaemonTestCase(unittest.TestCase):
    """One daemon and one scratch directory shared by a class's tests; the
    daemon must exit 0 on SIGTERM when the class is done. DAEMON_ARGS are
    its command-line options."""
    PREFIX = "fdemd-test-"
    DAEMON_ARGS = ()

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon(args=cls.DAEMON_ARGS).start()
        cls.tmp = tempfile.mkdtemp(prefix=cls.PREFIX)

    @classmethod
    def tearDownClass(cls):
        code, _ = cls.d.stop()
        cls.d.close()
        shutil.rmtree(cls.tmp, ignore_errors=True)
        assert code == 0, "fdemd exited %s on SIGTERM" % code

    def run_case(self, case, timeout=60):
        """Runs `case` to its end and downloads its result.h5 into the
        scratch directory: (final status, path of the file)."""
        st = self.d.create(case, start=True)
        st = self.d.wait_state(st["id"], ("finished", "failed", "stopped"), timeout=timeout)
        self.assertEqual(st["state"], "finished", st.get("error"))
        status, _, data = self.d.request("GET", "/cases/%s/result.h5" % st["id"])
        self.assertEqual(status, 200)
        path = os.path.join(self.tmp, st["id"] + ".h5")
        with open(path, "wb") as f:
            f.write(data)
        return st, path


class DimensionRunsTestCase(DaemonTestCase):
    """A class whose tests read one finished run per dimension: setUpClass
    runs case_of(2) and case_of(3) (CASE_OF, a function of the dimension)
    to their end, reads GET /cases/ID/<ROUTE> and downloads result.h5;
    each() yields (dimension, id, final status, JSON of ROUTE, path of the
    file), one subTest per dimension."""
    ROUTE = "status"
    RUN_TIMEOUT = 120

    @classmethod
    def case_of(cls, dimension):
        raise NotImplementedError

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.runs = {}
        for dimension in (2, 3):
            st = cls.d.create(cls.case_of(dimension), start=True)
            final = cls.d.wait_state(st["id"], ("finished", "failed", "stopped"),
                                     timeout=cls.RUN_TIMEOUT)
            status, body = cls.d.json("GET", "/cases/%s/%s" % (st["id"], cls.ROUTE))
            assert status == 200, (status, body)
            status, _, data = cls.d.request("GET", "/cases/%s/result.h5" % st["id"])
            assert status == 200, status
            path = os.path.join(cls.tmp, "%s-%dd.h5" % (cls.ROUTE, dimension))
            with open(path, "wb") as f:
                f.write(data)
            cls.runs[dimension] = (st["id"], final, body, path)

    def each(self):
        for dimension in (2, 3):
            with self.subTest(dimension=dimension):
                yield (dimension,) + self.runs[dimension]
