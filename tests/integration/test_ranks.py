"""The engine on N MPI ranks gives the same bits as one process (issue 37
items 1 and 2, contract 6.5).

build/tests/mpi/rank_compare (tests/mpi/rank_compare.c, built by `make test`
where mpicc exists) steps small 2D and 3D cases with contact, friction,
damping and fracture and prints, every few steps, a hash of the whole state
rank 0 would write (the checkpoint bytes: positions, velocities, element
history, joints, contact history, energies) and whether every rank holds
the same positions and velocities. The lines of 1, 2 (of 2 threads each), 3
and 4 ranks, and with FDEM_RANKS_FULL=1 (make test-ranks) of 8
oversubscribed and 2 of one thread, must equal those of one
plain process stepping with fdem_step; a rank engine that adds its halo
elements after its own (rank_compare --fault) must not, nor one that splits
the contact pair walk wrongly (--contact-fault: the ranks' lists applied in
reverse rank order, each rank given another share of the pairs every
step, or the springs the walk updates in place not handed over in the
steps or at the gather), and a walk failing on one rank fails the step on every rank. The
contact cases split their pair walk between the ranks (each rank
evaluates a share, on 2 ranks of 2 threads on both threads): every rank
evaluates some pairs, and each pair is evaluated once. A checkpoint written
on 3 ranks restarts on 2 with the same bits.

mpirun as root needs OMPI_ALLOW_RUN_AS_ROOT=1 and
OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 (set here).
"""
import json
import os
import shutil
import subprocess
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
STEPS, EVERY = "24", "4"
# the 2-rank run: 2 threads a rank, each rank's share of the contact walk on
# both from 64 pairs (a share of these small cases is under the 2048 a walk
# needs to take threads otherwise)
TWO = ("--threads", "2", "--split-threads-min", "64")
# 8 ranks (oversubscribed) and 2 ranks of one thread too: make test-ranks
FULL = os.environ.get("FDEM_RANKS_FULL") == "1"
# under the sanitizers (bin-san): 2 and 3 ranks only, unless FULL


def build_dir():
    """build/ for bin/fdemd, build-san/ for bin-san/fdemd."""
    bin_dir = os.path.dirname(os.path.abspath(os.environ.get("FDEMD_BIN", "bin/fdemd")))
    name = os.path.basename(bin_dir).replace("bin", "build", 1)
    return os.path.join(os.path.dirname(bin_dir), name)


SANITIZED = build_dir().endswith("-san") and not FULL


def mpi_env():
    env = dict(os.environ)
    env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_mpi_yield_when_idle="1", OMPI_MCA_btl="self,vader",
               OMPI_MCA_btl_vader_single_copy_mechanism="none", OMPI_MCA_rmaps_base_oversubscribe="1",
               OMP_WAIT_POLICY="passive")
    # OpenMPI keeps buffers to exit: not this project's leaks
    env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + ":detect_leaks=0"
    return env


def material():
    return {"density": 2000, "young": 1e8, "poisson": 0.25, "damping": 0.3, "friction": 0.4,
            "fracture": {"tensile_strength": 2e5, "cohesion": 6e5, "friction_angle": 30,
                         "energy_I": 1, "energy_II": 5}}


def case_2d():
    """An elastic block over four element blocks (so ranks share its
    border nodes and compute halo elements) strikes a fracturing one."""
    return {"name": "ranks-2d", "materials": {"rock": material()},
            "parts": [{"name": "left", "material": "rock",
                       "rectangle": {"origin": [-0.1, 0], "size": [0.1, 0.1],
                                     "divisions": [40, 40]},
                       "velocity": [20.0, 1.0]},
                      {"name": "right", "material": "rock", "fracture": True,
                       "rectangle": {"origin": [0.00002, 0.02], "size": [0.05, 0.05],
                                     "divisions": [24, 24]}}],
            "time": {"end": 1.0, "dt": "auto", "safety": 0.5}}


def elastic_material():
    return {"density": 2000, "young": 1e8, "poisson": 0.25, "damping": 0.3}


def case_2d_elastic():
    """One damped elastic block, no contact: the split update (border
    forces only); 2160 triangles, three element blocks. Fixed on its left edge, pressed on top, absorbing on the right,
    under gravity: the nodes every rank keeps."""
    return {"name": "ranks-2d-elastic", "materials": {"rock": elastic_material()},
            "parts": [{"name": "block", "material": "rock",
                       "rectangle": {"origin": [0, 0], "size": [0.1, 0.1], "divisions": [36, 30]},
                       "velocity": [3.0, -2.0]}],
            "gravity": [0, -9.81],
            "constraints": [{"box": [-0.001, -0.001, 0.001, 0.101], "fix": ["x", "y"]},
                            {"box": [-0.001, 0.099, 0.101, 0.101], "pressure": 1e6},
                            {"box": [0.099, -0.001, 0.101, 0.101], "absorb": True}],
            "time": {"end": 1.0, "dt": "auto", "safety": 0.5}}


def case_2d_blowing_up():
    """The elastic block under a pressure it cannot take: non-finite at
    step 6."""
    case = case_2d_elastic()
    case["name"] = "ranks-2d-blowing-up"
    case["constraints"][1]["pressure"] = 1e12
    return case


def case_3d_elastic():
    return {"name": "ranks-3d-elastic", "dimension": 3,
            "materials": {"rock": elastic_material()},
            "parts": [{"name": "block", "material": "rock",
                       "box": {"origin": [0, 0, 0], "size": [0.1, 0.1, 0.1],
                               "divisions": [7, 7, 7]},
                       "velocity": [3.0, -2.0, 1.0]}],
            "constraints": [{"box": [-0.001, -0.001, -0.001, 0.001, 0.101, 0.101],
                             "fix": ["x", "y", "z"]},
                            {"box": [-0.001, -0.001, 0.099, 0.101, 0.101, 0.101],
                             "pressure": 1e6}],
            "time": {"end": 1.0, "dt": "auto", "safety": 0.5}}


def case_3d():
    return {"name": "ranks-3d", "dimension": 3, "materials": {"rock": material()},
            "parts": [{"name": "left", "material": "rock",
                       "box": {"origin": [-0.1, 0, 0], "size": [0.1, 0.1, 0.1],
                               "divisions": [8, 8, 8]},
                       "velocity": [20.0, 1.0, 0.5]},
                      {"name": "right", "material": "rock", "fracture": True,
                       "box": {"origin": [0.00002, 0.035, 0.035], "size": [0.03, 0.03, 0.03],
                               "divisions": [3, 3, 3]}}],
            "time": {"end": 1.0, "dt": "auto", "safety": 0.5}}


def case_deep(dim):
    """A 10 mm steel block at 3000 m/s into a steel slab held at its ends,
    penalty young / 100 (tests/unit/test_warnings.c's case): pairs pass
    into one another, which the rank walking a pair finds and hands to all
    (the penetration warnings, not in the checkpoint: rank_compare prints
    their count and hash)."""
    steel = {"density": 7800, "young": 2e11, "poisson": 0.3, "penalty": 2e9}
    if dim == 2:
        parts = [{"name": "slab", "material": "steel",
                  "rectangle": {"origin": [0, 0], "size": [0.06, 0.01], "divisions": [12, 2]}},
                 {"name": "bullet", "material": "steel", "velocity": [0, -3000],
                  "rectangle": {"origin": [0.0263, 0.0125], "size": [0.01, 0.01],
                                "divisions": [2, 2]}}]
        fixed = [[-1, -1, 0.001, 1], [0.059, -1, 1, 1]]
    else:
        parts = [{"name": "slab", "material": "steel",
                  "box": {"origin": [0, 0, 0], "size": [0.04, 0.04, 0.01], "divisions": [8, 8, 2]}},
                 {"name": "bullet", "material": "steel", "velocity": [0, 0, -3000],
                  "box": {"origin": [0.0163, 0.0171, 0.0125], "size": [0.01, 0.01, 0.01],
                          "divisions": [2, 2, 2]}}]
        fixed = [[-1, -1, -1, 0.001, 1, 1], [0.039, -1, -1, 1, 1, 1]]
    axes = ["x", "y", "z"][:dim]
    return {"name": "ranks-%dd-deep" % dim, "dimension": dim, "materials": {"steel": steel},
            "parts": parts, "constraints": [{"box": b, "fix": axes} for b in fixed],
            "time": {"end": 1e-5}}


def same_failure(lines):
    """The lines without the element a failure names: each rank looks for
    the first non-finite value among the nodes it updates, one process
    among all."""
    return [l.split(" in element")[0] if " failed: " in l else l for l in lines]


class RanksSameBits(unittest.TestCase):
    """Every run is made once, in setUpClass, in this order (the restart
    needs the 3-rank run's checkpoint); the tests compare their lines."""

    @classmethod
    def setUpClass(cls):
        cls.exe = os.path.join(build_dir(), "tests", "mpi", "rank_compare")
        if not os.access(cls.exe, os.X_OK):
            raise unittest.SkipTest("%s not built (make test builds it where mpicc exists)" % cls.exe)
        if not shutil.which("mpirun"):
            raise unittest.SkipTest("mpirun not found (openmpi-bin, scripts/install-deps.sh)")
        cls.tmp = tempfile.mkdtemp(prefix="fdem-ranks-")
        cls.cases = []
        for name, doc in (("2d", case_2d()), ("3d", case_3d()), ("2d-elastic", case_2d_elastic()),
                          ("3d-elastic", case_3d_elastic())):
            path = os.path.join(cls.tmp, name + ".json")
            with open(path, "w") as f:
                json.dump(doc, f)
            cls.cases.append(path)
        # the last case must fail (rank_compare --expect-failure), on every
        # rank count at the same step
        cls.blowing = os.path.join(cls.tmp, "2d-blowing-up.json")
        with open(cls.blowing, "w") as f:
            json.dump(case_2d_blowing_up(), f)
        cls.failing = ["--expect-failure", cls.blowing]
        cls.deep_cases = []
        for dim in (2, 3):
            path = os.path.join(cls.tmp, "%dd-deep.json" % dim)
            with open(path, "w") as f:
                json.dump(case_deep(dim), f)
            cls.deep_cases.append(path)
        cls.checkpoint = os.path.join(cls.tmp, "2d-step10-3-ranks.bin")
        cls.checkpoint_split = os.path.join(cls.tmp, "2d-elastic-step10-3-ranks.bin")
        cls.stderr = {}
        cls.plain = cls.run_ranks(0, "--plain")
        # 2 ranks of 2 threads each; the 3-rank run saves the 2D cases after
        # step 10 ("--save-at 0 -" then turns saving off for the 3D cases)
        cls.ranked = {2: cls.run_ranks(2, *TWO),
                      3: cls.run_ranks(3, cases=["--save-at", "10", cls.checkpoint, cls.cases[0],
                                                 "--save-at", "0", "-", cls.cases[1],
                                                 "--save-at", "10", cls.checkpoint_split,
                                                 cls.cases[2], "--save-at", "0", "-",
                                                 cls.cases[3]] + cls.failing)}
        if not SANITIZED:  # the same code paths as 2 and 3 ranks, for ASan
            cls.ranked[1] = cls.run_ranks(1)
            cls.ranked[4] = cls.run_ranks(4)
        if FULL:
            cls.ranked[8] = cls.run_ranks(8)
            cls.ranked["2, one thread"] = cls.run_ranks(2)
        cls.restarted = cls.run_ranks(2, cases=["--restore", cls.checkpoint, cls.cases[0],
                                                "--restore", cls.checkpoint_split, cls.cases[2]])
        cls.fault = cls.run_ranks(4, "--fault")
        cls.contact_faults = {kind: cls.run_ranks(2, "--contact-fault", kind, cases=cls.cases[:2])
                              for kind in ("order", "rotate", "skip-sync", "skip-gather-sync")}
        cls.deep = {n: cls.run_ranks(n, *(() if n else ("--plain",)), cases=cls.deep_cases,
                                     tag=("deep",)) for n in (0, 2, 3)}
        cls.contact_fail = {n: cls.run_ranks(n, "--contact-fault", "fail",
                                             cases=["--expect-failure"] + cls.cases[:2])
                            for n in (2, 3)}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(getattr(cls, "tmp", ""), ignore_errors=True)

    @classmethod
    def run_ranks(cls, ranks, *flags, cases=None, tag=()):
        """The driver's lines on `ranks` ranks (0: one process, no mpirun);
        its stderr kept under (ranks,) + flags + tag."""
        cmd = [cls.exe, STEPS, EVERY] + list(flags) + (cases or cls.cases + cls.failing)
        if ranks:
            cmd = ["mpirun", "-np", str(ranks), "--oversubscribe"] + cmd
        p = subprocess.run(cmd, env=mpi_env(), capture_output=True, text=True, timeout=300)
        if p.returncode:
            raise AssertionError("%s failed (%d): %s %s" % (" ".join(cmd), p.returncode,
                                                           p.stdout[-2000:], p.stderr[-2000:]))
        cls.stderr[(ranks,) + flags + tag] = p.stderr
        return p.stdout.splitlines()

    def case_lines(self, lines, case):
        """The lines of one case: its "case" line and its steps."""
        start = lines.index("case " + case)
        rest = [i for i, l in enumerate(lines) if l.startswith("case ") and i > start]
        return lines[start:rest[0] if rest else len(lines)]

    def test_plain_run_contacts_and_breaks(self):
        """The cases exercise what the comparison claims: every state line
        differs from the last; in the first two contact forces act and
        joints break, in the elastic ones the block deforms."""
        for k, case in enumerate(self.cases):
            lines = self.case_lines(self.plain, case)[1:]
            self.assertEqual(len(lines), int(STEPS) // int(EVERY))
            states = [l.split()[3] for l in lines]
            self.assertEqual(len(set(states)), len(states))
            last = lines[-1].split()
            if k < 2:
                self.assertGreater(int(last[last.index("broken") + 1]), 0, lines[-1])
                self.assertGreater(int(last[last.index("contacts") + 1]), 0, lines[-1])
            else:
                self.assertGreater(float(last[last.index("elastic") + 1]), 0, lines[-1])

    def test_update_split_without_contact(self):
        """The elastic cases ran the split update (border forces only), the
        contact cases the replicated one: the comparison covers both."""
        err = self.stderr[(2,) + TWO]
        for k, case in enumerate(self.cases):
            mode = "split" if k >= 2 else "replicated"
            self.assertIn("update %s: %s" % (mode, case), err)

    def walked(self, key, case):
        """Per rank: the near pairs it evaluated and its walks on threads."""
        for line in self.stderr[key].splitlines():
            if line.startswith("contact pairs walked ") and line.endswith(": " + case):
                pairs, threads = line[len("contact pairs walked "):-len(": " + case)].split(" (walks on threads ")
                return [int(n) for n in pairs.split()], [int(n) for n in threads.rstrip(")").split()]
        self.fail("no contact pairs walked line for %s on %s" % (case, key))

    def test_contact_walk_split(self):
        """The contact cases split their pair walk: on 2 ranks each rank
        evaluated a share (on its 2 threads), and the shares add up to the
        same pairs on 2, 3 (and 4) ranks: each pair once."""
        for case in self.cases[:2]:
            with self.subTest(case=case):
                pairs, threads = self.walked((2,) + TWO, case)
                self.assertEqual(len(pairs), 2)
                self.assertTrue(all(n > 0 for n in pairs), pairs)
                self.assertTrue(all(n > 0 for n in threads), threads)
                self.assertLess(max(pairs), 0.6 * sum(pairs))
                for key in [k for k in self.stderr if k and k[0] in (3, 4) and len(k) == 1]:
                    self.assertEqual(sum(self.walked(key, case)[0]), sum(pairs), key)
        for case in self.cases[2:]:  # no contact: nothing to split
            self.assertFalse([l for l in self.stderr[(2,) + TWO].splitlines()
                              if l.startswith("contact pairs walked") and l.endswith(": " + case)])

    def test_contact_walk_split_wrongly_differs(self):
        """The ranks' lists applied in reverse rank order, each rank
        evaluating another share every step (the near pairs' hints it keeps
        go stale), or the springs the walk updates in place not handed over
        in the steps (before a detection, a break's mending or a rebuild of
        the near list) or at the gather before output: the comparison must
        see each."""
        plain = [l for case in self.cases[:2] for l in self.case_lines(self.plain, case)]
        for kind, lines in self.contact_faults.items():
            with self.subTest(fault=kind):
                self.assertEqual(len(lines), len(plain))
                self.assertNotEqual(lines, plain)

    def test_a_failed_contact_walk_fails_every_rank_together(self):
        """The last rank's walk failing at step 9 (as if its lists could not
        grow) fails the step on every rank with one process's bits until
        then; the run goes on to its next case (no rank left waiting)."""
        for ranks, lines in self.contact_fail.items():
            with self.subTest(ranks=ranks):
                expected = []
                for case in self.cases[:2]:
                    plain = self.case_lines(self.plain, case)
                    expected += [l for l in plain if not l.startswith("step ") or
                                 int(l.split()[1]) < 9]
                    expected.append("step 9 failed: out of memory in contact detection at step 9")
                self.assertEqual(lines, expected)

    def test_penetrations_found_alike_on_any_rank_count(self):
        """Pairs passing into one another are looked at by the rank that
        walked them and kept by every rank in pair order: rank 0 takes the
        same penetrations (count and hash on each line) as one process, in
        2D and 3D, and the cases have some."""
        plain = self.deep[0]
        for case in self.deep_cases:
            last = self.case_lines(plain, case)[-1].split()
            self.assertGreater(int(last[last.index("deep") + 1]), 0, last)
        for ranks in (2, 3):
            with self.subTest(ranks=ranks):
                self.assertEqual(self.deep[ranks], plain)

    def test_same_bits_on_1_2_3_4_ranks(self):
        """(and 8, and 2 of one thread, with FDEM_RANKS_FULL=1: make test-ranks;
        2 and 3 under the sanitizers)"""
        for ranks, lines in self.ranked.items():
            with self.subTest(ranks=ranks):
                if ranks == 3:  # the line of the step it saved after
                    lines = [l for l in lines if not l.startswith("step 10 ")]
                self.assertEqual(same_failure(lines), same_failure(self.plain))

    def test_checkpoint_of_3_ranks_restarts_on_2(self):
        """The 2D cases (replicated and split update) saved after step 10 on
        3 ranks and restarted from that checkpoint on 2 go on with the plain
        run's bits."""
        expected = []
        for case in (self.cases[0], self.cases[2]):
            lines = self.case_lines(self.plain, case)
            expected += [lines[0]] + [l for l in lines[1:] if int(l.split()[1]) > 10]
        self.assertEqual(self.restarted, expected)

    def test_a_non_finite_step_fails_every_rank_together(self):
        """A split run that goes non-finite (on 1, 2, 3 and 4 ranks) fails on
        every rank at the step one process fails, with its bits until then,
        and the run goes on to end (no rank left waiting in a collective). Here every rank sees it at once (the
        elastic energy, totalled from all blocks, is not finite); a value
        going non-finite on one rank's nodes alone reaches the others
        through the update's verdict (step_share.update_done), which this
        case does not single out."""
        plain = self.case_lines(self.plain, self.blowing)
        self.assertRegex(plain[-1], r"^step 6 failed: the solution became non-finite at step 6 ")
        for ranks, lines in self.ranked.items():
            with self.subTest(ranks=ranks):
                self.assertEqual(same_failure(self.case_lines(lines, self.blowing)),
                                 same_failure(plain))

    def test_border_sums_in_another_order_differ(self):
        """Each rank adding its halo elements after its own blocks forms
        border nodes' sums in another order: the comparison must see it."""
        self.assertNotEqual(self.fault, self.plain)


@unittest.skipUnless(FULL, "the bundled examples on 3 ranks: make test-ranks")
class ExamplesSameBits(unittest.TestCase):
    """Every bundled example (fluid, stages and excavation, ramps,
    constraints, absorbing boundaries, fracture regions, gmsh meshes, piles,
    2D and 3D) stepped 40 steps on 3 ranks gives one process's bits."""

    def test_examples_on_3_ranks(self):
        exe = os.path.join(build_dir(), "tests", "mpi", "rank_compare")
        if not os.access(exe, os.X_OK) or not shutil.which("mpirun"):
            self.skipTest("rank_compare or mpirun missing")
        examples = sorted(f for f in os.listdir(os.path.join(ROOT, "examples")) if f.endswith(".json"))
        for name in examples:
            path = os.path.join(ROOT, "examples", name)
            with self.subTest(example=name):
                runs = []
                for cmd in ([exe, "40", "10", "--plain", path],
                            ["mpirun", "-np", "3", "--oversubscribe", exe, "40", "10", path]):
                    p = subprocess.run(cmd, env=mpi_env(), capture_output=True, text=True,
                                       timeout=600)
                    self.assertEqual(p.returncode, 0, p.stderr[-2000:])
                    runs.append(p.stdout.splitlines())
                self.assertEqual(len(runs[0]), 5)
                self.assertEqual(runs[1], runs[0])


if __name__ == "__main__":
    unittest.main()
