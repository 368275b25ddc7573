"""The web page (contract 6.3, issue 35 items 2-4): GET / and /ui/ served
from web/ with a strict Content-Security-Policy and no way out of the
folder; GET /cases/ID/mesh.bin, the binary frame the page draws, checked
number for number against result.h5; and the page itself driven in
headless Chromium against a real daemon (token prompt, live list, a pause,
the 2D and 3D views drawn, plots with data, nothing from another host, the
token in no URL). The browser tests skip, saying why, where Chromium,
chromedriver or Selenium is missing (scripts/install-deps.sh installs them).

FDEMD_WEB_SCREENSHOTS=DIR saves a screenshot of each view in DIR (the
README's come from `FDEMD_WEB_SCREENSHOTS=docs/img`).
"""
import json
import os
import shutil
import struct
import tempfile
import time
import unittest

from fdemd_harness import ROOT, SLOW, Daemon, DaemonTestCase, fetched_result, tiny_case
from test_fluid import fluid_case

TOKEN = "web-test-token-7f3a"
HEADER = struct.Struct("<8sIIIIIIIIdqIIQII")
SECTION = struct.Struct("<16sIIII")
SHAPE = ("cells", "joints", "joint_elements", "faces", "face_element", "face_joint", "node_id",
         "element_id", "joint_id", "position0")
NONE = 0xFFFFFFFF
# each facet's local nodes, outward (core/analysis/boundary_facets.c)
LOCAL_FACETS = {2: [[0, 1], [1, 2], [2, 0]], 3: [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]}


def decode_frame(data):
    """The frame as numpy arrays (docs/api.md, "Binary mesh frames"):
    header values, "shape" (the mesh's sections), "fields", "position"."""
    import numpy as np
    (magic, version, dim, nodes, elements, joints, index, snapshots, sections, time_, step,
     deformed, faces, key, flags, _) = HEADER.unpack_from(data, 0)
    assert magic == b"FDEMMESH", magic
    out = {"version": version, "dimension": dim, "nodes": nodes, "elements": elements,
           "joints": joints, "index": index, "snapshots": snapshots, "time": time_,
           "step": step, "deformed": deformed, "faces": faces, "key": "%016x" % key,
           "surface": bool(flags & 1), "with_shape": bool(flags & 2), "fields": {}, "shape": {}}
    o = HEADER.size
    for _ in range(sections):
        name, at, width, kind, items = SECTION.unpack_from(data, o)
        o += SECTION.size
        name = name.rstrip(b"\0").decode()
        count = (nodes, elements, joints, faces)[at]
        assert items == count, (name, items, count)
        a = np.frombuffer(data, dtype="<u4" if kind == 1 else "<f4", count=items * width,
                          offset=o).reshape(items, width)
        o += 4 * items * width
        if name in SHAPE:
            out["shape"][name] = a
        elif name == "position":
            out["position"] = a
        else:
            out["fields"][name] = (at, a)
    assert o == len(data), (o, len(data))
    return out


def visible_facets(cells, joints, damage, active):
    """The facets a surface frame must carry, found here independently of
    the daemon (dicts of sorted node ids): [(element, outward nodes)]."""
    import numpy as np
    d = cells.shape[1] - 1
    facets = cells[:, LOCAL_FACETS[d]].reshape(-1, d)
    element = np.repeat(np.arange(len(cells)), d + 1)
    alive = np.ones(len(cells), bool) if active is None else active != 0
    where = {}
    for f, row in enumerate(facets.tolist()):
        where.setdefault(tuple(sorted(row)), []).append(f)
    hidden = np.zeros(len(facets), bool)
    for fs in where.values():
        if len(fs) == 2 and alive[element[fs]].all():
            hidden[fs] = True
    for j, row in enumerate(joints.tolist()):
        a, b = where.get(tuple(sorted(row[:d]))), where.get(tuple(sorted(row[d:])))
        if (damage is None or damage[j] < 1) and a and b and alive[element[[a[0], b[0]]]].all():
            hidden[[a[0], b[0]]] = True
    return [(int(element[f]), tuple(facets[f].tolist()))
            for f in range(len(facets)) if alive[element[f]] and not hidden[f]]


def fracturing_case(name="frac", end=2e-4):
    """A small fracturing block hit hard on a fixed base: joints, damage,
    fragments and every field the frame carries."""
    case = tiny_case(name, end=end, divisions=(6, 6), interval=end / 4)
    case["materials"]["rock"]["fracture"] = {"tensile_strength": 1e5, "cohesion": 3e5,
                                             "friction_angle": 30, "energy_I": 1, "energy_II": 5}
    case["parts"][0]["fracture"] = True
    case["parts"][0]["velocity"] = [0, -30]
    case["output"]["fields"] = ["position", "velocity", "stress", "principal_stress",
                                "displacement", "strain"]
    return case


def box_case_3d(name="box3d", divisions=(3, 3, 3), end=2e-4):
    return {"name": name, "dimension": 3,
            "materials": {"rock": {"density": 2700, "young": 3e10, "poisson": 0.25,
                                   "fracture": {"tensile_strength": 1e5, "cohesion": 3e5,
                                                "friction_angle": 30, "energy_I": 1,
                                                "energy_II": 5}}},
            "parts": [{"name": "block", "material": "rock", "fracture": True,
                       "box": {"origin": [0, 0, 0], "size": [0.1, 0.1, 0.1],
                               "divisions": list(divisions)}, "velocity": [0, 0, -20]}],
            "constraints": [{"box": [-1, -1, -0.001, 1, 1, 0.001], "fix": ["x", "y", "z"]}],
            "time": {"end": end}, "output": {"interval": end / 4,
                                             "fields": ["position", "velocity", "stress"]}}


class WebFilesTest(DaemonTestCase):
    """GET / and /ui/: the page's files, open without the token."""
    DAEMON_ARGS = ("--token", TOKEN)

    def test_page_served_without_token_with_csp(self):
        status, headers, body = self.d.request("GET", "/", token=None)
        self.assertEqual(status, 200)
        self.assertTrue(headers["content-type"].startswith("text/html"), headers)
        csp = headers["content-security-policy"]
        self.assertIn("default-src 'self'", csp)
        self.assertNotIn("unsafe-inline", csp)
        self.assertEqual(headers["x-content-type-options"], "nosniff")
        self.assertIn(b'src="/ui/app.js"', body)
        self.assertNotIn(b"<script>", body)  # no inline script: the CSP would refuse it
        status, headers, body = self.d.request("GET", "/ui/app.js", token=None)
        self.assertEqual(status, 200)
        self.assertTrue(headers["content-type"].startswith("text/javascript"), headers)
        status, headers, _ = self.d.request("HEAD", "/ui/vendor/three/three.module.js", token=None)
        self.assertEqual(status, 200)
        self.assertGreater(int(headers["content-length"]), 100000)
        # the API behind the page still wants the token
        self.assertEqual(self.d.request("GET", "/cases", token=None)[0], 401)

    def test_nothing_outside_the_folder(self):
        readme = open(os.path.join(ROOT, "README.md"), "rb").read(40)
        for path in ("/ui/../README.md", "/ui/%2e%2e/README.md", "/ui/..%2fREADME.md",
                     "/ui/vendor/../../README.md", "/ui/%2E%2E%2F%2E%2E%2FREADME.md",
                     "/ui/.hidden", "/ui//app.js", "/ui/", "/ui/app.js%00.png",
                     "/ui/vendor", "/ui/app.js/", "/ui/..\\README.md", "/ui/~/x",
                     "/ui/" + "a/" * 200 + "b", "/index.html", "/../README.md"):
            status, _, body = self.d.request("GET", path, token=None)
            self.assertIn(status, (400, 401, 404), path)
            self.assertNotIn(readme, body, path)
        self.assertEqual(self.d.request("POST", "/ui/app.js", token=None)[0], 405)
        self.assertEqual(self.d.request("GET", "/?token=x", token=None)[0], 400)

    def test_symlink_out_of_the_folder_refused(self):
        web = os.path.join(self.tmp, "web")
        os.makedirs(web)
        with open(os.path.join(web, "index.html"), "w") as f:
            f.write("<!doctype html><title>t</title>")
        secret = os.path.join(self.tmp, "secret.txt")
        with open(secret, "w") as f:
            f.write("not for the web")
        os.symlink(secret, os.path.join(web, "leak.txt"))
        d = Daemon(args=["--web", web]).start()
        try:
            self.assertEqual(d.request("GET", "/")[0], 200)
            status, _, body = d.request("GET", "/ui/leak.txt")
            self.assertEqual(status, 404)
            self.assertNotIn(b"not for the web", body)
        finally:
            self.assertEqual(d.stop()[0], 0)
            d.close()

    def test_missing_folder_is_a_404_that_says_where(self):
        d = Daemon(args=["--web", os.path.join(self.tmp, "nowhere")]).start()
        try:
            status, body = d.json("GET", "/")
            self.assertEqual(status, 404)
            self.assertIn("--web", body["detail"])
            self.assertEqual(d.json("GET", "/health")[0], 200)
        finally:
            self.assertEqual(d.stop()[0], 0)
            d.close()


class MeshFrameTest(DaemonTestCase):
    """GET /cases/ID/mesh.bin against result.h5, 2D and 3D."""

    def check_frame(self, st, f, index):
        import numpy as np
        status, headers, data = self.d.request("GET", "/cases/%s/mesh.bin?snapshot=%d" % (st["id"], index))
        self.assertEqual(status, 200, data[:300])
        self.assertEqual(headers["content-type"], "application/octet-stream")
        fr = decode_frame(data)
        dim = st["dimension"]
        self.assertEqual((fr["version"], fr["dimension"], fr["index"]), (2, dim, index))
        self.assertEqual((fr["surface"], fr["with_shape"], fr["faces"]), (False, True, 0))
        self.assertEqual(fr["snapshots"], st["snapshots"])
        self.assertEqual(fr["time"], f["/snapshots/time"][index])
        self.assertEqual(fr["step"], f["/snapshots/step"][index])
        cells = f["/mesh/tetrahedra" if dim == 3 else "/mesh/triangles"][:]
        shape = fr["shape"]
        np.testing.assert_array_equal(shape["cells"], cells)
        np.testing.assert_array_equal(shape["joints"], f["/mesh/joints"][:])
        self.check_joint_elements(shape["joint_elements"], shape["joints"], cells, dim)
        # float32 of the stored float64: exactly what numpy's rounding gives
        np.testing.assert_array_equal(shape["position0"], f["/mesh/position0"][:].astype(np.float32))
        np.testing.assert_array_equal(fr["position"], f["/snapshots/position"][index].astype(np.float32))
        self.assertEqual(fr["deformed"], 1)
        for name in ("velocity", "stress", "damage", "fragment", "principal_stress", "displacement",
                     "strain"):
            if "/snapshots/" + name not in f:
                self.assertNotIn(name, fr["fields"])
                continue
            at, values = fr["fields"][name]
            want = f["/snapshots/" + name][index].astype(np.float32)
            np.testing.assert_array_equal(values, want.reshape(values.shape), name)
        return fr

    def check_joint_elements(self, joint_elements, joint_nodes, cells, dim):
        """Each joint side's nodes are nodes of the element given for it."""
        for j, (a, b) in enumerate(joint_elements.tolist()):
            for side, e in ((0, a), (1, b)):
                self.assertNotEqual(e, NONE, "joint %d side %d" % (j, side))
                self.assertTrue(set(joint_nodes[j][side * dim:(side + 1) * dim].tolist())
                                <= set(cells[e].tolist()), (j, side, e))

    def check_surface(self, st, f, index):
        """The surface form against result.h5: the facets found here
        independently, the carried items' values number for number; then
        the same frame for a page that holds its shape."""
        import numpy as np
        url = "/cases/%s/mesh.bin?snapshot=%d&surface=true" % (st["id"], index)
        status, _, data = self.d.request("GET", url)
        self.assertEqual(status, 200, data[:300])
        fr = decode_frame(data)
        self.assertTrue(fr["surface"] and fr["with_shape"])
        dim, shape = st["dimension"], fr["shape"]
        cells = f["/mesh/tetrahedra" if dim == 3 else "/mesh/triangles"][:]
        joints = f["/mesh/joints"][:]
        damage = f["/snapshots/damage"][index]
        active = f["/snapshots/active"][index] if "/snapshots/active" in f else None
        want = visible_facets(cells, joints, damage, active)
        node_id, element_id = shape["node_id"][:, 0], shape["element_id"][:, 0]
        joint_id = shape["joint_id"][:, 0]
        got = [(int(element_id[e]), tuple(node_id[v].tolist()))
               for e, v in zip(shape["face_element"][:, 0], shape["faces"])]
        self.assertEqual(sorted(got), sorted(want))
        self.assertEqual(fr["faces"], len(want))
        # a face on a joint says which (a broken one, here)
        for k, j in enumerate(shape["face_joint"][:, 0].tolist()):
            if j != NONE:
                self.assertGreaterEqual(damage[joint_id[j]], 1.0)
        self.assertEqual(sorted(set(node_id.tolist())), sorted(set(v for _, vs in want for v in vs)))
        self.assertEqual(sorted(element_id.tolist()), sorted(set(e for e, _ in want)))
        je = shape["joint_elements"]
        local = np.full(len(cells), NONE, dtype=np.int64)
        local[element_id] = np.arange(len(element_id))
        for row, j in zip(je.tolist(), joint_id.tolist()):
            self.assertTrue(any(e != NONE for e in row))
            for side, e in enumerate(row):
                if e != NONE:
                    self.assertTrue(set(joints[j][side * dim:(side + 1) * dim].tolist())
                                    <= set(cells[element_id[e]].tolist()))
        np.testing.assert_array_equal(shape["position0"],
                                      f["/mesh/position0"][:][node_id].astype(np.float32))
        np.testing.assert_array_equal(fr["position"],
                                      f["/snapshots/position"][index][node_id].astype(np.float32))
        np.testing.assert_array_equal(fr["fields"]["stress"][1],
                                      f["/snapshots/stress"][index][element_id].astype(np.float32))
        np.testing.assert_array_equal(fr["fields"]["damage"][1][:, 0],
                                      damage[joint_id].astype(np.float32))
        # the page holds this shape: only positions and fields come
        status, _, again = self.d.request("GET", url + "&shape=" + fr["key"])
        kept = decode_frame(again)
        self.assertEqual((kept["with_shape"], kept["key"], kept["shape"]), (False, fr["key"], {}))
        np.testing.assert_array_equal(kept["position"], fr["position"])
        self.assertLess(len(again), len(data))
        # a key of another shape gets the shape
        other = "%016x" % (int(fr["key"], 16) ^ 1)
        self.assertTrue(decode_frame(self.d.request("GET", url + "&shape=" + other)[2])["with_shape"])
        return fr

    def test_frame_2d_matches_result_file(self):
        st = self.d.create(fracturing_case(), start=True)
        st = self.d.wait_state(st["id"], "finished", timeout=60)
        with fetched_result(self.d, st["id"]) as f:
            self.assertGreater(f["/mesh/joints"].shape[0], 0)
            for index in (0, st["snapshots"] - 1):
                fr = self.check_frame(st, f, index)
            self.assertEqual(sorted(fr["fields"]), ["damage", "displacement", "fragment",
                                                    "principal_stress", "strain", "stress",
                                                    "velocity"])
            self.assertGreater(fr["fields"]["damage"][1].max(), 0)
            self.check_surface(st, f, st["snapshots"] - 1)
        # the last snapshot without ?snapshot=, and only the fields asked for
        status, _, data = self.d.request("GET", "/cases/%s/mesh.bin?fields=damage,stress" % st["id"])
        fr = decode_frame(data)
        self.assertEqual(fr["index"], st["snapshots"] - 1)
        self.assertEqual(sorted(fr["fields"]), ["damage", "stress"])
        for query, code in (("?snapshot=%d" % st["snapshots"], 404), ("?snapshot=-1", 400),
                            ("?snapshot=x", 400), ("?fields=pressure", 400), ("?frame=1", 400),
                            ("?surface=maybe", 400), ("?shape=12", 400),
                            ("?shape=0123456789abcdeg", 400)):
            status, body = self.d.json("GET", "/cases/%s/mesh.bin%s" % (st["id"], query))
            self.assertEqual(status, code, query)
            self.assertIn(body["title"], ("Not found", "Bad request"))
        self.assertEqual(self.d.json("GET", "/cases/0123456789abcdef/mesh.bin")[0], 404)
        self.assertEqual(self.d.json("POST", "/cases/%s/mesh.bin" % st["id"])[0], 405)

    def test_frame_3d_while_running_and_after(self):
        st = self.d.create(box_case_3d(end=2.5e-4), start=True)  # 2e-3 took 57 s here
        # read from the open file of the running case
        st = self.d.wait(st["id"], lambda s: s["snapshots"] >= 2 or s["state"] == "finished",
                         timeout=60, what="a second snapshot")
        status, _, data = self.d.request("GET", "/cases/%s/mesh.bin?snapshot=1" % st["id"])
        self.assertEqual(status, 200)
        running = decode_frame(data)
        st = self.d.wait_state(st["id"], "finished", timeout=120)
        with fetched_result(self.d, st["id"]) as f:
            fr = self.check_frame(st, f, 1)
            self.assertEqual(running["position"].tobytes(), fr["position"].tobytes())
            self.check_frame(st, f, st["snapshots"] - 1)
            surface = self.check_surface(st, f, st["snapshots"] - 1)
            self.assertGreater(len([j for j in surface["shape"]["face_joint"][:, 0] if j != NONE]),
                               0, "no crack face in the last snapshot")

    def test_frame_fluid_fields(self):
        """A case with fluid: fluid_pressure and aperture per joint, as in
        result.h5, in both forms."""
        import numpy as np
        st = self.d.create(fluid_case(2), start=True)
        st = self.d.wait_state(st["id"], "finished", timeout=60)
        with fetched_result(self.d, st["id"]) as f:
            index = st["snapshots"] - 1
            for query, ids in (("", None), ("&surface=true", "joint_id")):
                status, _, data = self.d.request(
                    "GET", "/cases/%s/mesh.bin?fields=fluid_pressure,aperture%s" % (st["id"], query))
                self.assertEqual(status, 200, data[:300])
                fr = decode_frame(data)
                self.assertEqual(sorted(fr["fields"]), ["aperture", "fluid_pressure"])
                for name in ("fluid_pressure", "aperture"):
                    at, values = fr["fields"][name]
                    want = f["/snapshots/" + name][index]
                    if ids:
                        want = want[fr["shape"][ids][:, 0]]
                    self.assertEqual(at, 2)
                    np.testing.assert_array_equal(values[:, 0], want.astype(np.float32), name)
            pressure = f["/snapshots/fluid_pressure"][index]
            self.assertGreater(pressure.max(), 0)
            # the surface form asked for a fluid field shows the faces of
            # the joints holding fluid too, as it shows those of cracks
            shape = fr["shape"]
            cells, joints = f["/mesh/triangles"][:], f["/mesh/joints"][:]
            opened = np.where(pressure != 0, 1.0, f["/snapshots/damage"][index])
            want = visible_facets(cells, joints, opened, None)
            got = [(int(shape["element_id"][e, 0]), tuple(shape["node_id"][v, 0].tolist()))
                   for e, v in zip(shape["face_element"][:, 0], shape["faces"])]
            self.assertEqual(sorted(got), sorted(want))
            wet = [j for j in shape["face_joint"][:, 0].tolist()
                   if j != NONE and pressure[shape["joint_id"][j, 0]] != 0]
            self.assertGreater(len(wet), 0, "no face of a joint holding fluid")

    def test_large_frame_loads_quickly(self):
        """A 2D mesh of 100,352 triangles, created (snapshot 0): the whole
        frame arrives. How fast is printed, not asserted (a test waits on
        states, never on wall time); the figure is in docs/api.md."""
        case = tiny_case("big", divisions=(224, 224))
        st = self.d.create(case)
        self.assertEqual(st["elements"], 100352)
        times = []
        for _ in range(3):
            t0 = time.monotonic()
            status, _, data = self.d.request("GET", "/cases/%s/mesh.bin" % st["id"])
            times.append(time.monotonic() - t0)
            self.assertEqual(status, 200)
        fr = decode_frame(data)
        self.assertEqual(fr["elements"], 100352)
        print("mesh.bin of 100352 triangles: %.1f MB in %.3f s (median of 3)"
              % (len(data) / 1e6, sorted(times)[1]))


# ------------------------------------------------------------------ browser

def browser_missing():
    """Why the browser tests cannot run here, or None."""
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "python3-selenium is not installed (scripts/install-deps.sh installs it)"
    for tool in ("chromium", "chromedriver"):
        if not shutil.which(tool):
            return "%s is not installed (scripts/install-deps.sh installs it)" % tool
    return None


def start_browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    opts = webdriver.ChromeOptions()
    opts.binary_location = shutil.which("chromium")
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
                "--window-size=1500,1400", "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"):
        opts.add_argument(arg)
    opts.set_capability("goog:loggingPrefs", {"performance": "ALL", "browser": "ALL"})
    return webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=opts)


# Counts the pixels of a canvas (2D or WebGL) that are not white, and the
# distinct colours among them, by drawing it into a 2D canvas.
PIXELS_JS = """
const src = document.getElementById(arguments[0]);
const c = document.createElement('canvas'); c.width = src.width; c.height = src.height;
const g = c.getContext('2d'); g.drawImage(src, 0, 0);
const d = g.getImageData(0, 0, c.width, c.height).data;
let drawn = 0; const colours = new Set();
for (let i = 0; i < d.length; i += 4) {
  if (d[i] < 250 || d[i + 1] < 250 || d[i + 2] < 250) { drawn++; colours.add(d[i] << 16 | d[i + 1] << 8 | d[i + 2]); }
}
return [drawn, colours.size, c.width * c.height];
"""


@unittest.skipIf(browser_missing(), browser_missing() or "")
class WebBrowserTest(unittest.TestCase):
    """The page in headless Chromium against a daemon with a token."""

    @classmethod
    def setUpClass(cls):
        if SLOW > 1:
            # CI's time: under the sanitizers the browser's minutes are
            # Chromium's, not the daemon's; the routes the page uses are
            # checked there by WebFilesTest, MeshFrameTest and test_stream
            raise unittest.SkipTest("the browser test runs in the normal build's pass")
        cls.d = Daemon(token=TOKEN).start()
        cls.base = "http://127.0.0.1:%d" % cls.d.port
        cls.shots = os.environ.get("FDEMD_WEB_SCREENSHOTS")
        # a finished 3D case, a finished 2D fracturing case, and a 2D case
        # that would run for a minute (the test pauses it), sized once the
        # others are done so that their load does not shorten it
        cls.box = cls.d.create(box_case_3d(divisions=(4, 4, 4)), start=True)
        cls.frac = cls.d.create(fracturing_case(), start=True)
        # a parametric study of the fracturing case: a weaker rock
        weaker = fracturing_case("frac weaker")
        weaker["materials"]["rock"]["fracture"]["tensile_strength"] = 5e4
        cls.weaker = cls.d.create(weaker, start=True)
        cls.fluid = cls.d.create(fluid_case(2), start=True)
        for st in (cls.box, cls.frac, cls.weaker, cls.fluid):
            cls.d.wait_state(st["id"], "finished", timeout=120)
        cls.long = cls.d.create(cls.d.case_lasting(60.0, name="long running"), start=True)
        cls.browser = start_browser()
        cls.browser.set_script_timeout(20)

    @classmethod
    def tearDownClass(cls):
        cls.browser.quit()
        code, _ = cls.d.stop()
        cls.d.close()
        assert code == 0, "fdemd exited %s on SIGTERM" % code

    def wait_for(self, script, what, timeout=20.0, *args):
        deadline = time.monotonic() + timeout * SLOW
        while True:
            value = self.browser.execute_script(script, *args)
            if value:
                return value
            if time.monotonic() > deadline:
                raise AssertionError("timed out waiting for " + what)
            time.sleep(0.05)

    def shot(self, name, scroll_to=None):
        if self.shots:
            if scroll_to:
                self.browser.execute_script("document.getElementById(arguments[0]).scrollIntoView()",
                                            scroll_to)
            os.makedirs(self.shots, exist_ok=True)
            self.browser.save_screenshot(os.path.join(self.shots, "web-%s.png" % name))

    def daemon_streams(self):
        """Whether the daemon answers GET /stream with an event stream
        (contract 6.3; the page polls without it)."""
        conn = self.d.connection(timeout=5)
        try:
            conn.request("GET", "/stream", headers={"Authorization": "Bearer " + TOKEN})
            resp = conn.getresponse()
            return resp.status == 200 and resp.getheader("Content-Type", "").startswith(
                "text/event-stream")
        finally:
            conn.close()

    def row(self, case_id):
        return "document.querySelector('#cases tr[data-id=\"%s\"]')" % case_id

    def click(self, selector):
        self.browser.execute_script("document.querySelector(arguments[0]).click()", selector)

    def command(self, case_id, name):
        self.wait_for("return document.querySelector(arguments[0]) !== null", "the %s button" % name,
                      20.0, '#cases tr[data-id="%s"] button[data-command="%s"]' % (case_id, name))
        self.click('#cases tr[data-id="%s"] button[data-command="%s"]' % (case_id, name))

    def extend_stop_delete(self, case_id):
        """The extend, stop and delete buttons, each checked at the daemon
        (the page's prompt and confirm answered as a user would)."""
        b = self.browser
        end = self.d.status(case_id)["end_time"]
        b.execute_script("window.prompt = () => arguments[0]; window.confirm = () => true;",
                         repr(2 * end))
        self.command(case_id, "extend")
        st = self.d.wait(case_id, lambda s: s["end_time"] == 2 * end, what="the extended end")
        self.assertEqual(st["state"], "paused")
        self.command(case_id, "stop")
        self.d.wait_state(case_id, "stopped")
        self.wait_for("return %s.querySelector('.state').textContent === 'stopped'"
                      % self.row(case_id), "the row to say stopped")
        self.command(case_id, "delete")
        self.wait_deleted(case_id)
        self.wait_for("return %s === null" % self.row(case_id), "the row to go")

    def wait_deleted(self, case_id):
        deadline = time.monotonic() + 20 * SLOW
        while self.d.json("GET", "/cases/" + case_id)[0] != 404:
            self.assertLess(time.monotonic(), deadline, "the case is still there")
            time.sleep(0.05)

    def downloads(self, case_id):
        """The download buttons: the files the browser saves are the
        daemon's, byte for byte."""
        folder = tempfile.mkdtemp(prefix="fdemd-web-dl-")
        try:
            self.browser.execute_cdp_cmd("Browser.setDownloadBehavior",
                                         {"behavior": "allow", "downloadPath": folder})
            for label, route, saved in (("case", "case", case_id + ".json"),
                                        ("result.h5", "result.h5", case_id + "-result.h5")):
                want = self.d.request("GET", "/cases/%s/%s" % (case_id, route))[2]
                self.browser.execute_script(
                    "[...%s.querySelectorAll('.files button')].find(b => b.textContent === "
                    "arguments[0]).click()" % self.row(case_id), label)
                path = os.path.join(folder, saved)
                deadline = time.monotonic() + 20 * SLOW
                while not (os.path.exists(path) and os.path.getsize(path) == len(want)):
                    self.assertLess(time.monotonic(), deadline, "no download of " + saved)
                    time.sleep(0.05)
                with open(path, "rb") as f:
                    self.assertEqual(f.read(), want, saved)
        finally:
            shutil.rmtree(folder, ignore_errors=True)

    def test_page(self):
        b = self.browser
        # 1. the token prompt, then the list
        b.get(self.base + "/")
        self.wait_for("return !document.getElementById('token-panel').hidden", "the token prompt")
        self.shot("token")
        b.execute_script("window.notReloaded = true;"
                         "document.getElementById('token-input').value = arguments[0];"
                         "document.getElementById('token-form').requestSubmit();", TOKEN)
        self.wait_for("return %s !== null" % self.row(self.long["id"]), "the list")
        for st in (self.box, self.frac):
            self.wait_for("return %s !== null" % self.row(st["id"]), "case " + st["id"])
        # live through the stream when the daemon has one, else by polling
        mode = "live (stream)" if self.daemon_streams() else "live (polling every 1 s)"
        self.wait_for("return document.getElementById('mode').textContent === %s" % json.dumps(mode),
                      "the page to say " + mode)

        # 2. progress advancing without a reload
        progress = "return Number(%s.querySelector('progress').value)" % self.row(self.long["id"])
        first = b.execute_script(progress)
        self.wait_for(progress + " > %r" % (first + 0.02), "progress to advance", 20)
        self.shot("list")

        # 3. a pause from the page
        self.click('#cases tr[data-id="%s"] button[data-command="pause"]' % self.long["id"])
        self.d.wait_state(self.long["id"], "paused", timeout=20)
        self.wait_for("return %s.querySelector('.state').textContent === 'paused'"
                      % self.row(self.long["id"]), "the row to say paused")
        self.assertTrue(b.execute_script("return window.notReloaded === true"))
        self.extend_stop_delete(self.long["id"])
        self.downloads(self.frac["id"])

        # 4. the 2D view of the fracturing case, drawn, and its plots
        self.click('#cases tr[data-id="%s"] td.name' % self.frac["id"])
        last = self.d.status(self.frac["id"])["snapshots"] - 1
        self.wait_for("return document.body.dataset.frameDrawn === 'yes' && "
                      "document.body.dataset.frameIndex === '%d'" % last, "the 2D frame")
        drawn, colours, total = b.execute_script(PIXELS_JS, "view2d")
        self.assertGreater(drawn, total * 0.05, "the 2D canvas is (nearly) blank")
        self.assertGreater(colours, 5, "the 2D canvas has one colour")
        points = "return (document.querySelector('#plot-energy .uplot') || {dataset: {}}).dataset.points"
        self.assertGreater(int(self.wait_for(points, "the energy plot")), 4)
        for plot in ("events", "sieve", "load"):
            self.wait_for("return Number((document.querySelector('#plot-%s .uplot') || "
                          "{dataset: {}}).dataset.points) > 0" % plot, "the %s plot" % plot)
        self.shot("2d", "case-view")

        # 5. the 3D view
        self.click('#cases tr[data-id="%s"] td.name' % self.box["id"])
        self.wait_for("return !document.getElementById('view3d').hidden && "
                      "document.body.dataset.frameDrawn === 'yes' && "
                      "document.getElementById('view-title').textContent.includes('%s')"
                      % self.box["id"], "the 3D frame")
        self.wait_for("return Number((document.querySelector('#plot-sieve .uplot') || "
                      "{dataset: {}}).dataset.points) > 1", "the 3D case's sieve curve")
        drawn, colours, total = b.execute_script(PIXELS_JS, "view3d")
        self.assertGreater(drawn, total * 0.02, "the 3D canvas is (nearly) blank")
        self.assertGreater(colours, 5, "the 3D canvas has one colour")
        self.shot("3d", "case-view")
        # the same snapshot again: the page holds its shape, so the daemon
        # sends positions and fields only, and the view is drawn from them
        self.assertEqual(b.execute_script("return document.body.dataset.frameShape"), "sent")
        sent = int(b.execute_script("return document.body.dataset.frameBytes"))
        b.execute_script("document.body.dataset.frameDrawn = 'no';"
                         "const s = document.getElementById('snapshot');"
                         "s.dispatchEvent(new Event('change'));")
        self.wait_for("return document.body.dataset.frameDrawn === 'yes' && "
                      "document.body.dataset.frameShape === 'kept'", "a frame without the shape")
        self.assertLess(int(b.execute_script("return document.body.dataset.frameBytes")), sent)
        again = b.execute_script(PIXELS_JS, "view3d")
        self.assertEqual(again[:2], [drawn, colours])

        # 5b. a case with fluid: fluid pressure on the crack lines, and the
        # source pressure's plot when the daemon writes that history series
        self.click('#cases tr[data-id="%s"] td.name' % self.fluid["id"])
        self.wait_for("return document.body.dataset.frameDrawn === 'yes' && "
                      "document.getElementById('view-title').textContent.includes('%s')"
                      % self.fluid["id"], "the fluid case's frame")
        options = self.wait_for("const o = [...document.getElementById('field').options]"
                                ".map(o => o.value); return o.length && o", "the field menu")
        self.assertIn("fluid_pressure", options)
        self.assertIn("aperture", options)
        b.execute_script("const m = document.getElementById('field'); m.value = 'fluid_pressure';"
                         "m.dispatchEvent(new Event('change'));")
        self.wait_for("return document.body.dataset.frameField === 'fluid_pressure'",
                      "the fluid pressure drawn")
        lo, hi = b.execute_script("return [document.getElementById('legend-lo').textContent,"
                                  "document.getElementById('legend-hi').textContent]")
        self.assertGreater(float(hi), float(lo))
        self.assertGreater(float(hi), 0)
        drawn, colours, total = b.execute_script(PIXELS_JS, "view2d")
        self.assertGreater(colours, 5, "no coloured joint lines")
        rows = self.d.json("GET", "/cases/%s/history" % self.fluid["id"])[1]["rows"]
        if rows and "fluid" in rows[0]:
            self.wait_for("return !document.getElementById('plot-fluid').hidden && Number(("
                          "document.querySelector('#plot-fluid .uplot') || {dataset: {}})"
                          ".dataset.points) > 1", "the source pressure plot")
        else:
            self.wait_for("return Number((document.querySelector('#plot-energy .uplot') || "
                          "{dataset: {}}).dataset.points) > 1", "the fluid case's plots")
            self.assertTrue(b.execute_script("return document.getElementById('plot-fluid').hidden"))
        self.shot("fluid", "case-view")

        # 6. a clone: the document edited, its diff against the parent shown,
        # the new case made from it and showing the same diff
        self.click('#cases tr[data-id="%s"] button[data-command="clone"]' % self.frac["id"])
        self.wait_for("return !document.getElementById('clone-panel').hidden && "
                      "document.getElementById('clone-text').value.includes('tensile_strength')",
                      "the clone editor")
        b.execute_script("const t = document.getElementById('clone-text');"
                         "const doc = JSON.parse(t.value); doc.materials.rock.fracture.tensile_strength = 2e5;"
                         "doc.name = 'frac stronger'; t.value = JSON.stringify(doc, null, 2);"
                         "t.dispatchEvent(new Event('input'));")
        diff = b.execute_script("return document.getElementById('clone-diff').textContent")
        self.assertIn("~ /materials/rock/fracture/tensile_strength: 100000 -> 200000", diff)
        self.assertIn('~ /name: "frac" -> "frac stronger"', diff)
        known = {c["id"] for c in self.d.json("GET", "/cases")[1]["cases"]}
        self.click("#clone-go")
        clone = self.wait_for("return document.getElementById('parent-diff').textContent"
                              ".includes('tensile_strength') && document.getElementById('view-title')"
                              ".textContent", "the clone's view with its diff")
        new = [c for c in self.d.json("GET", "/cases")[1]["cases"] if c["id"] not in known]
        self.assertEqual(len(new), 1, clone)
        status, doc = self.d.json("GET", "/cases/%s/case" % new[0]["id"])
        self.assertEqual(doc["materials"]["rock"]["fracture"]["tensile_strength"], 2e5)
        self.assertEqual(new[0]["name"], "frac stronger")

        # 7. submit: pasted, sized by a dry run first, then stored
        self.click('button[data-tab="submit"]')
        self.assertTrue(b.execute_script("return document.getElementById('submit-go').disabled"))
        b.execute_script("const t = document.getElementById('submit-text'); t.value = arguments[0];"
                         "t.dispatchEvent(new Event('input'));",
                         json.dumps(tiny_case("pasted", divisions=(4, 4))))
        self.click("#submit-dry")
        sizing = self.wait_for("const r = document.getElementById('submit-result').textContent;"
                               "return r.startsWith('dry run') && r", "the dry run")
        self.assertIn("32 elements", sizing)
        self.assertIn("estimated", sizing)
        self.click("#submit-go")
        stored = self.wait_for("const r = document.getElementById('submit-result').textContent;"
                               "return r.startsWith('stored as') && r", "the stored case")
        self.assertEqual(self.d.status(stored.split()[2])["name"], "pasted")
        self.click('button[data-tab="cases"]')

        # 8. compare: two cases on one plot
        for st in (self.frac, self.weaker):
            self.click('#cases tr[data-id="%s"] input[type=checkbox]' % st["id"])
        self.click('button[data-tab="compare"]')
        self.wait_for("return [...document.getElementById('compare-series').options]"
                      ".some(o => o.value === 'energy:fracture')", "the series menu")
        b.execute_script("const m = document.getElementById('compare-series');"
                         "m.value = 'energy:fracture'; m.dispatchEvent(new Event('change'));")
        # one line per case (the legend lists x and the two cases), on the
        # chosen series (its name is the y axis label)
        self.wait_for("return document.querySelectorAll('#plot-compare .u-legend .u-series')"
                      ".length === 3 && document.querySelector('#plot-compare .uplot').dataset.y"
                      " === 'energy fracture'", "the comparison plot of two cases")
        self.assertGreater(int(b.execute_script(
            "return document.querySelector('#plot-compare .uplot').dataset.points")), 4)
        self.shot("compare")

        # 9. nothing from another host, the token in no URL, no CSP refusal
        urls = []
        for entry in b.get_log("performance"):
            msg = json.loads(entry["message"])["message"]
            if msg["method"] == "Network.requestWillBeSent":
                urls.append(msg["params"]["request"]["url"])
        urls += b.execute_script("return performance.getEntriesByType('navigation')"
                                 ".concat(performance.getEntriesByType('resource')).map(e => e.name)")
        self.assertTrue(urls)
        for url in urls:
            self.assertTrue(url.startswith(self.base + "/") or url.startswith("blob:" + self.base)
                            or url.startswith("data:") or url == "about:blank", url)
            self.assertNotIn(TOKEN, url)
        console = b.get_log("browser")
        self.assertFalse([e for e in console if "Content Security Policy" in e["message"]], console)
        self.assertFalse([e for e in console if TOKEN in e["message"]], console)
        # the errors expected: the 401 that made the page ask for the token,
        # and a 404 of /stream from a daemon without it (the page then polls)
        self.assertFalse([e for e in console if e["level"] == "SEVERE" and
                          "401 (Unauthorized)" not in e["message"] and
                          not ("/stream" in e["message"] and "404" in e["message"])], console)
        with open(self.d.log_path, "rb") as f:
            self.assertNotIn(TOKEN.encode(), f.read())


if __name__ == "__main__":
    unittest.main()
