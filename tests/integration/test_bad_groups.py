"""Bad physical-group keys (contract 5.3: a gmsh part's "materials" and
"discontinuities", the {"part", "group"} selector, a fracture block's
"variation") are each answered with 422 and a JSON Pointer at the key, and
a good case with all of them runs through the daemon to the end."""
import copy
import json
import os
import unittest

from fdemd_harness import Daemon

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")


def read(path):
    with open(os.path.join(ROOT, path)) as f:
        return f.read()


FRACTURE = {"tensile_strength": 1e6, "cohesion": 3e6, "friction_angle": 30,
            "energy_I": 10, "energy_II": 50}


def bar_case():
    """The two-group bar of tests/data/bar_groups.geo, fracturing, with a
    material per group, a joint set on the interface, Weibull strengths and
    group selectors."""
    rock = {"density": 2600, "young": 1e10, "poisson": 0.2,
            "fracture": dict(FRACTURE, variation={"distribution": "weibull", "modulus": 4,
                                                  "seed": 3})}
    return {
        "name": "groups",
        "materials": {"rock": rock, "hard": dict(rock, young=4e10), "soft": {"density": 2000,
                                                                            "young": 1e9,
                                                                            "poisson": 0.2}},
        "parts": [{"name": "bar", "material": "rock", "fracture": True,
                   "gmsh": read("tests/data/bar_groups_v41.msh"),
                   "materials": {"stiff": "hard"},
                   "discontinuities": {"interface": {"tensile_strength": 1e5}}}],
        "constraints": [{"part": "bar", "group": "left", "fix": ["x", "y"]},
                        {"part": "bar", "group": "right", "velocity": [1, 0]}],
        "time": {"end": 2e-4},
        "output": {"interval": 1e-4, "fields": ["position", "damage"]},
    }


def with_edit(path, value):
    case = bar_case()
    target = case
    for key in path[:-1]:
        target = target[key]
    if value is None:
        del target[path[-1]]
    else:
        target[path[-1]] = value
    return case


class BadGroupsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon().start()

    @classmethod
    def tearDownClass(cls):
        code, _ = cls.d.stop()
        cls.d.close()
        assert code == 0, "fdemd exited with %s" % code

    def refused(self, case, pointer, *words):
        status, _, data = self.d.request("POST", "/cases", case,
                                         {"Content-Type": "application/json"})
        self.assertEqual(status, 422, data[:300])
        problem = json.loads(data)
        pointers = [e["pointer"] for e in problem["errors"]]
        self.assertIn(pointer, pointers)
        text = json.dumps(problem).lower()
        for word in words:
            self.assertIn(word.lower(), text)

    def test_good_case_runs(self):
        case = self.d.create(bar_case(), start=True)
        status = self.d.wait_state(case["id"], "finished")
        self.assertEqual(status["state"], "finished")

    def test_unknown_group_in_materials(self):
        self.refused(with_edit(["parts", 0, "materials"], {"granite": "hard"}),
                     "/parts/0/materials/granite", "no physical group", "soft")

    def test_group_of_another_dimension(self):
        self.refused(with_edit(["parts", 0, "materials"], {"left": "hard"}),
                     "/parts/0/materials/left", "curve group")
        self.refused(with_edit(["parts", 0, "discontinuities"], {"stiff": {"cohesion": 1e5}}),
                     "/parts/0/discontinuities/stiff", "surface group")

    def test_material_undefined(self):
        self.refused(with_edit(["parts", 0, "materials"], {"stiff": "basalt"}),
                     "/parts/0/materials/stiff", "unknown material")

    def test_group_material_without_fracture(self):
        self.refused(with_edit(["parts", 0, "materials"], {"stiff": "soft"}),
                     "/parts/0/materials/stiff", "fracture")

    def test_materials_on_a_generated_part(self):
        case = bar_case()
        del case["parts"][0]["gmsh"]
        case["parts"][0]["rectangle"] = {"size": [1, 1], "divisions": [2, 2]}
        self.refused(case, "/parts/0/materials", "gmsh")

    def test_discontinuities_on_non_fracturing_part(self):
        self.refused(with_edit(["parts", 0, "fracture"], False),
                     "/parts/0/discontinuities", "fracture")

    def test_bad_joint_set_parameters(self):
        self.refused(with_edit(["parts", 0, "discontinuities", "interface"],
                               {"tensile_strength": -1}),
                     "/parts/0/discontinuities/interface/tensile_strength", "> 0")
        self.refused(with_edit(["parts", 0, "discontinuities", "interface"], {"strength": 1}),
                     "/parts/0/discontinuities/interface/strength")
        self.refused(with_edit(["parts", 0, "discontinuities", "interface"], {}),
                     "/parts/0/discontinuities/interface", "at least one")

    def test_joint_set_on_the_boundary(self):
        self.refused(with_edit(["parts", 0, "discontinuities"], {"left": {"cohesion": 1e5}}),
                     "/parts/0", "no interior edge")

    def test_group_selector(self):
        self.refused(with_edit(["constraints", 0, "group"], "top"),
                     "/constraints/0/group", "no physical group")
        self.refused(with_edit(["constraints", 0, "group"], 3), "/constraints/0/group")
        case = bar_case()
        case["constraints"][0] = {"box": [-1, -1, 0.01, 1], "group": "left", "fix": ["x"]}
        self.refused(case, "/constraints/0/group", "part")
        case = bar_case()
        case["parts"].append({"name": "plate", "material": "soft",
                              "rectangle": {"origin": [3, 0], "size": [1, 1],
                                            "divisions": [2, 2]}})
        case["constraints"][0]["part"] = "plate"
        self.refused(case, "/constraints/0/group", "gmsh")

    def test_bad_variation(self):
        base = ["materials", "rock", "fracture", "variation"]
        self.refused(with_edit(base + ["distribution"], "normal"),
                     "/materials/rock/fracture/variation/distribution", "weibull")
        self.refused(with_edit(base + ["modulus"], 0),
                     "/materials/rock/fracture/variation/modulus")
        self.refused(with_edit(base + ["modulus"], "big"),
                     "/materials/rock/fracture/variation/modulus")
        self.refused(with_edit(base + ["seed"], -1), "/materials/rock/fracture/variation/seed")
        self.refused(with_edit(base + ["seed"], 1.5), "/materials/rock/fracture/variation/seed")
        self.refused(with_edit(base + ["spread"], 1), "/materials/rock/fracture/variation/spread")
        self.refused(with_edit(base + ["distribution"], None),
                     "/materials/rock/fracture/variation", "distribution")
        self.refused(with_edit(["parts", 0, "discontinuities", "interface", "variation"],
                               {"distribution": "weibull", "modulus": -2}),
                     "/parts/0/discontinuities/interface/variation/modulus")

    def test_dt_probe_of_a_grouped_part(self):
        """A dt above the stable step with another problem makes the daemon
        probe the sound parts (case_probe.c); a gmsh part with groups,
        materials and joint sets went to the probe without its groups
        changing hands, and both documents freed them (double free: the
        daemon aborted)."""
        case = with_edit(["constraints", 0, "part"], "no such part")
        case["time"]["dt"] = 1.0
        self.refused(case, "/constraints/0/part")
        self.refused(case, "/time/dt", "stable")
        status, _, _ = self.d.request("GET", "/cases")
        self.assertEqual(status, 200)


if __name__ == "__main__":
    unittest.main()
