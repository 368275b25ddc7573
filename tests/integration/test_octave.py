"""The Octave commands of docs/results.md ("Reading results in Octave"),
run as they stand there on a fetched result, print what h5py reads from
the same file. Skipped (saying so) without octave-cli; scripts/install-deps.sh
installs it."""
import os
import re
import shutil
import subprocess
import tempfile
import unittest

import h5py
import numpy as np

from fdemd_harness import ROOT, Daemon, tiny_case

OCTAVE = shutil.which("octave-cli")

# The test has no display: triplot only checks and records its arguments.
TRIPLOT_STAND_IN = """function triplot(tri, x, y)
  assert(size(tri, 2) == 3 && min(tri(:)) >= 1 && max(tri(:)) <= numel(x));
  assert(numel(x) == numel(y));
  printf('triplot %d %d\\n', size(tri, 1), numel(x));
end
"""

PRINT = """
printf('time %s\\n', sprintf('%.17g ', t));
printf('xy %s\\n', sprintf('%d ', size(xy)));
printf('last %s\\n', sprintf('%.17g ', xy(:, :, end)));
printf('tri %s\\n', sprintf('%d ', tri'));
printf('frag %s\\n', sprintf('%d ', frag));
printf('sig %s\\n', sprintf('%.17g ', sig));
printf('ek %s\\n', sprintf('%.17g ', ek));
"""


def documented_block():
    with open(os.path.join(ROOT, "docs", "results.md")) as f:
        text = f.read()
    section = text.split("## Reading results in Octave", 1)[1]
    return re.search(r"```octave\n(.*?)```", section, re.S).group(1)


def numbers(line, kind=float):
    return np.array([kind(v) for v in line.split()[1:]])


@unittest.skipUnless(OCTAVE, "octave-cli is not installed (Debian's octave package)")
class OctaveTest(unittest.TestCase):
    def test_documented_commands_read_a_result(self):
        work = tempfile.mkdtemp(prefix="fdemd-octave-")
        d = Daemon().start()
        try:
            case = tiny_case("octave", end=0.001, divisions=(3, 3))
            case["output"]["fields"] = ["position", "velocity", "stress"]
            st = d.wait_state(d.create(case, start=True)["id"], "finished")
            status, _, data = d.request("GET", "/cases/%s/result.h5" % st["id"])
            self.assertEqual(status, 200)
            with open(os.path.join(work, "collision.h5"), "wb") as f:
                f.write(data)
            with open(os.path.join(work, "triplot.m"), "w") as f:
                f.write(TRIPLOT_STAND_IN)
            with open(os.path.join(work, "doc.m"), "w") as f:
                f.write(documented_block() + PRINT)
            r = subprocess.run([OCTAVE, "--no-gui", "--quiet", "--eval", "doc"], cwd=work,
                               capture_output=True, text=True, timeout=120)
        finally:
            d.stop()
            d.close()
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        out = {line.split()[0]: line for line in r.stdout.splitlines() if line.strip()}
        with h5py.File(os.path.join(work, "collision.h5"), "r") as f:
            np.testing.assert_array_equal(numbers(out["time"]), f["/snapshots/time"][...])
            s, n, _ = f["/snapshots/position"].shape
            self.assertEqual(list(numbers(out["xy"], int)), [2, n, s])
            # column-major 2 x N: x0 y0 x1 y1 ... = the (N, 2) rows in C order
            np.testing.assert_array_equal(numbers(out["last"]),
                                          f["/snapshots/position"][-1].ravel())
            tri = f["/mesh/triangles"][...]
            np.testing.assert_array_equal(numbers(out["tri"], int), (tri + 1).ravel())
            self.assertEqual(out["triplot"].split()[1:], [str(len(tri)), str(n)])
            np.testing.assert_array_equal(numbers(out["frag"], int),
                                          f["/snapshots/fragment"][-1])
            np.testing.assert_array_equal(numbers(out["sig"]), f["/snapshots/stress"][-1].ravel())
            np.testing.assert_array_equal(numbers(out["ek"]), f["/snapshots/kinetic_energy"][...])
        self.assertIn("block", r.stdout)  # disp(r.mesh.part_names)
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    unittest.main()
