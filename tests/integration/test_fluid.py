"""test_fluid.py - fluid in the fractures (contract 6.4) through the real
daemon: a fracturing block fed at its centre, in 2D and 3D. The dry run
and the status report the flow's step and subcycles; the status' "fluid"
holds the injected and stored volumes (equal, the block holding no fluid at
t = 0) and a source pressure; energy gains fluid_work and
fluid_dissipation and the residual stays below 1 % of the fluid's work;
result.h5 has /snapshots/fluid_pressure and /snapshots/aperture (S, J),
result.xdmf shows them on the joints block, fdemctl status prints a
`fluid` line; the history series (GET /cases/ID/history, /history/fluid/*
and energy/fluid_* in result.h5, fdemctl history's CSV) carry each
injection's source pressure and injected volume; status.json keeps the
fluid across a restart of the daemon; bad input is one 422 with a
problem at each pointer. Waits for states, never for wall time."""
import json
import os
import unittest

from fdemd_harness import Daemon, DaemonTestCase


def fluid_case(dimension=2, end=1.5e-3, inject=2e-3):
    if dimension == 3:
        shape = {"box": {"origin": [-0.5] * 3, "size": [1, 1, 1], "divisions": [4, 4, 4]}}
        source = [-0.01] * 3 + [0.01] * 3
        inject = 5e-4
    else:
        shape = {"rectangle": {"origin": [-0.5, -0.5], "size": [1, 1], "divisions": [8, 8]}}
        source = [-0.01, -0.01, 0.01, 0.01]
    return {
        "name": "fluid-%dd" % dimension, "dimension": dimension,
        "materials": {"rock": {"density": 2500, "young": 1e10, "poisson": 0.2, "damping": 0.2,
                               "fracture": {"tensile_strength": 1e6, "cohesion": 3e6,
                                            "friction_angle": 30, "energy_I": 20,
                                            "energy_II": 100, "aperture0": 1e-4}}},
        "fluid": {"viscosity": 1e-3, "bulk_modulus": 1e8, "density": 1000},
        "parts": [dict({"name": "rock", "material": "rock", "fracture": True}, **shape)],
        "constraints": [{"box": source, "inject": inject,
                         "amplitude": [[0, 0], [1e-4, 1]]}],
        "time": {"end": end},
        "output": {"interval": end / 4},
    }


class FluidTest(DaemonTestCase):
    def check_case(self, dimension):
        case = fluid_case(dimension)
        status, dry = self.d.json("POST", "/cases?dry_run=true", case)
        self.assertEqual(status, 200, dry)
        self.assertGreater(dry["fluid_step"], 0)
        self.assertGreaterEqual(dry["fluid_subcycles"], 1)
        created = self.d.create(case)
        stored0 = created["fluid"]["stored_volume"]  # the fed joints start full, at p = 0
        self.assertEqual(created["fluid"]["injected_volume"], 0)
        self.assertGreater(stored0, 0)
        status, _ = self.d.json("POST", "/cases/%s/start" % created["id"])
        self.assertEqual(status, 200)
        st = self.d.wait_state(created["id"], ("finished", "failed", "stopped"), timeout=60)
        self.assertEqual(st["state"], "finished", st.get("error"))
        path = os.path.join(self.tmp, st["id"] + ".h5")
        status, _, data = self.d.request("GET", "/cases/%s/result.h5" % st["id"])
        self.assertEqual(status, 200)
        with open(path, "wb") as f:
            f.write(data)
        fluid, energy = st["fluid"], st["energy"]
        print("  %dD: %s; fluid_work %.4g, dissipation %.4g, residual %.3g" %
              (dimension, json.dumps(fluid), energy["fluid_work"], energy["fluid_dissipation"],
               energy["residual"]), flush=True)
        self.assertGreater(fluid["injected_volume"], 0)
        self.assertAlmostEqual(fluid["stored_volume"] - stored0, fluid["injected_volume"],
                               delta=1e-9 * fluid["stored_volume"])
        self.assertGreater(fluid["source_pressure"], 0)
        self.assertGreaterEqual(fluid["fluid_subcycles"], 1)
        self.assertGreater(energy["fluid_work"], 0)
        self.assertLess(abs(energy["residual"]), 0.01 * energy["fluid_work"])
        import h5py
        with h5py.File(path, "r") as f:
            joints = f["/mesh/joints"].shape[0]
            snaps = f["/snapshots/time"].shape[0]
            for name in ("fluid_pressure", "aperture"):
                self.assertEqual(f["/snapshots/" + name].shape, (snaps, joints))
            self.assertGreater(f["/snapshots/fluid_pressure"][-1].max(), 0)
            self.assertGreaterEqual(f["/snapshots/aperture"][-1].min(), 1e-4)
        shown = self.d.fdemctl("status", st["id"])
        self.assertEqual(shown.returncode, 0, shown.stderr)
        self.assertIn("source pressure", [l for l in shown.stdout.splitlines()
                                          if l.startswith("fluid")][0])
        status, _, xdmf = self.d.request("GET", "/cases/%s/result.xdmf" % st["id"])
        self.assertEqual(status, 200)
        self.assertIn(b'Name="fluid_pressure"', xdmf)
        self.assertIn(b'Name="aperture"', xdmf)
        self.check_history(st, path)

    def check_history(self, st, path):
        """The injection's source pressure and injected volume as history
        series: the last row (taken with the last snapshot, at the end) holds
        the status' figures; a constraint that does not inject has none."""
        status, body = self.d.json("GET", "/cases/%s/history" % st["id"])
        self.assertEqual(status, 200, body)
        rows = body["rows"]
        self.assertGreater(len(rows), 2)
        last = rows[-1]
        self.assertEqual(last["fluid"]["injected_volume"], [st["fluid"]["injected_volume"]])
        self.assertEqual(last["fluid"]["source_pressure"], [st["fluid"]["source_pressure"]])
        self.assertEqual(last["energy"]["fluid_work"], st["energy"]["fluid_work"])
        self.assertEqual(rows[0]["fluid"]["injected_volume"], [0])
        import h5py
        with h5py.File(path, "r") as f:
            h = f["/history"]
            n = len(h["time"])
            self.assertEqual(n, len(rows))
            volume = h["fluid/injected_volume"][:, 0]
            self.assertEqual(h["fluid/source_pressure"].shape, (n, 1))
            self.assertTrue((volume[1:] >= volume[:-1]).all())
            self.assertEqual(volume[-1], st["fluid"]["injected_volume"])
            self.assertEqual(h["energy/fluid_dissipation"][-1], st["energy"]["fluid_dissipation"])
        csv = self.d.fdemctl("history", st["id"])
        self.assertEqual(csv.returncode, 0, csv.stderr)
        lines = csv.stdout.splitlines()
        header = lines[0].split(",")
        for column in ("c0_source_pressure", "c0_injected_volume", "fluid_work",
                       "fluid_dissipation"):
            self.assertIn(column, header)
        values = dict(zip(header, lines[-1].split(",")))
        self.assertEqual(float(values["c0_injected_volume"]), st["fluid"]["injected_volume"])

    def test_fluid_status_survives_a_restart(self):
        """status.json keeps the fluid figures: a daemon started again on the
        same directory shows the finished case's "fluid" and fluid energies
        (they were dropped before: the status then said "fluid": null)."""
        first = Daemon().start()
        again = None
        try:
            case = fluid_case(2, end=2e-4)
            st = first.create(case, start=True)
            st = first.wait_state(st["id"], ("finished", "failed", "stopped"), timeout=60)
            self.assertEqual(st["state"], "finished", st.get("error"))
            rows = first.json("GET", "/cases/%s/history" % st["id"])[1]["rows"]
            code, _ = first.stop()
            self.assertEqual(code, 0)
            again = Daemon(data_dir=first.data_dir).start()
            shown = again.status(st["id"])
            self.assertEqual(shown["fluid"], st["fluid"])
            for term in ("fluid_work", "fluid_dissipation"):
                self.assertEqual(shown["energy"][term], st["energy"][term])
            # the history's fluid series read back from the file on disk
            self.assertEqual(again.json("GET", "/cases/%s/history" % st["id"])[1]["rows"], rows)
            self.assertIn("fluid", rows[-1])
            code, _ = again.stop()
            self.assertEqual(code, 0)
        finally:
            if again:
                again.close()
            first.close()

    def test_fluid_2d(self):
        self.check_case(2)

    def test_fluid_3d(self):
        self.check_case(3)

    def test_no_fluid_no_fluid_status(self):
        case = fluid_case(2)
        del case["fluid"]
        del case["constraints"]
        del case["materials"]["rock"]["fracture"]["aperture0"]
        case["time"]["end"] = 1e-5
        st, path = self.run_case(case)
        self.assertIsNone(st["fluid"])
        self.assertNotIn("fluid_work", st["energy"])

    def test_bad_fluid(self):
        case = fluid_case(2)
        case["fluid"]["viscosity"] = -1
        case["fluid"]["bulk_modulus"] = 0
        case["materials"]["rock"]["fracture"]["pore_pressure"] = {"value": 1e6, "gradient": "x"}
        case["constraints"][0]["inject"] = -1
        status, body = self.d.json("POST", "/cases", case)
        self.assertEqual(status, 422, body)
        pointers = {e["pointer"] for e in body["errors"]}
        for want in ("/fluid/viscosity", "/fluid/bulk_modulus",
                     "/materials/rock/fracture/pore_pressure/gradient", "/constraints/0/inject"):
            self.assertIn(want, pointers, body)
        case = fluid_case(2)
        case["parts"][0]["fracture"] = False
        status, body = self.d.json("POST", "/cases", case)
        self.assertEqual(status, 422, body)
        self.assertIn("/constraints/0", {e["pointer"] for e in body["errors"]}, body)


if __name__ == "__main__":
    unittest.main()
