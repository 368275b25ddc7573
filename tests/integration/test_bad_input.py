"""Bad requests are each answered with a clear 4xx (problem+json naming
what and where) and change nothing: the case already stored before them
is untouched and no case is added."""
import json
import socket
import unittest

from fdemd_harness import Daemon, tiny_case


def degenerate_mesh_case():
    case = tiny_case("degenerate")
    case["parts"].append({"name": "flat", "material": "rock",
                          "mesh": {"nodes": [[1, 1], [2, 2], [3, 3]], "triangles": [[0, 1, 2]]}})
    return case


def out_of_range_mesh_case():
    case = tiny_case("range")
    case["parts"].append({"name": "bad", "material": "rock",
                          "mesh": {"nodes": [[1, 1], [2, 1], [1, 2]], "triangles": [[0, 1, 3]]}})
    return case


def edit(path, value, name="bad"):
    """tiny_case() with the value at a JSON path (list of keys) replaced."""
    case = tiny_case(name)
    target = case
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return case


class BadInputTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon(args=["--max-upload", "1M"]).start()
        cls.kept = cls.d.create(tiny_case("keep-me", end=0.0003), start=True)
        cls.d.wait_state(cls.kept["id"], "finished")
        cls.kept = cls.d.status(cls.kept["id"])

    @classmethod
    def tearDownClass(cls):
        code, _ = cls.d.stop()
        cls.d.close()
        assert code == 0, "fdemd exited with %s" % code

    def tearDown(self):
        # Nothing bad got in and the stored case is as it was.
        status, body = self.d.json("GET", "/cases")
        self.assertEqual(status, 200)
        self.assertEqual(body["cases"], [self.kept])

    def assertProblem(self, status, headers, data, expected, pointer=None, words=()):
        self.assertEqual(status, expected, data[:300])
        self.assertEqual(headers.get("content-type"), "application/problem+json")
        problem = json.loads(data)
        self.assertEqual(problem["type"], "about:blank")
        self.assertEqual(problem["status"], expected)
        self.assertTrue(problem["title"])
        self.assertTrue(problem["detail"])
        self.assertIsInstance(problem["errors"], list)
        text = json.dumps(problem).lower()
        for word in words:
            self.assertIn(word.lower(), text)
        if pointer is not None:
            pointers = [e["pointer"] for e in problem["errors"]]
            self.assertTrue(any(p.startswith(pointer) for p in pointers), (pointer, pointers))
            for e in problem["errors"]:
                self.assertTrue(e["message"])
        return problem

    def post(self, body, expected, pointer=None, words=()):
        status, headers, data = self.d.request("POST", "/cases", body,
                                               {"Content-Type": "application/json"})
        return self.assertProblem(status, headers, data, expected, pointer, words)

    # ------------------------------------------------------------ 400
    def test_malformed_json(self):
        self.post(b'{"name": "x", ', 400)
        self.post(b"", 400)
        self.post(b"\xff\xfe garbage", 400)

    def test_deeply_nested_json(self):
        self.post(b"[" * 100000, 400)
        self.post(b'{"a":' * 50000 + b"1" + b"}" * 50000, 400)

    def test_nan_literal(self):
        text = json.dumps(tiny_case("nan")).replace('"density": 2700', '"density": NaN')
        self.assertIn("NaN", text)
        self.post(text.encode(), 400)
        text = json.dumps(tiny_case("inf")).replace('"density": 2700', '"density": Infinity')
        self.post(text.encode(), 400)

    def test_not_an_object(self):
        self.post(b"[]", 422)
        self.post(b'"case"', 400)  # not a JSON document for the parser

    # ------------------------------------------------------------ 422
    def test_negative_and_zero_sizes(self):
        self.post(edit(["parts", 0, "rectangle", "size"], [-0.1, 0.1]), 422, "/parts/0/rectangle/size")
        self.post(edit(["parts", 0, "rectangle", "size"], [0.1, 0]), 422, "/parts/0/rectangle/size")
        self.post(edit(["parts", 0, "rectangle", "divisions"], [0, 4]), 422, "/parts/0/rectangle/divisions")
        self.post(edit(["time", "end"], -1), 422, "/time/end")
        self.post(edit(["materials", "rock", "density"], 0), 422, "/materials/rock/density")

    def test_poisson_half(self):
        self.post(edit(["materials", "rock", "poisson"], 0.5), 422, "/materials/rock/poisson")

    def test_degenerate_and_out_of_range_triangles(self):
        self.post(degenerate_mesh_case(), 422, "/parts/1")
        self.post(out_of_range_mesh_case(), 422, "/parts/1")

    def test_every_problem_in_one_answer(self):
        """A dt above the stable step (found by building a model) comes in
        the same 422 as a bad constraint, material and part (found while
        reading), each at its own pointer."""
        case = tiny_case("all-at-once")
        case["materials"]["soft"] = {"density": -1, "young": 1e9, "poisson": 0.2}
        case["parts"].append({"name": "soft", "material": "soft",
                              "rectangle": {"origin": [0, 0.2], "size": [0.1, 0.1],
                                            "divisions": [2, 2]}})
        case["parts"].append({"name": "no-shape", "material": "rock"})
        case["constraints"][0]["fix"] = ["x", "w"]
        case["time"]["dt"] = 1e-3
        problem = self.post(case, 422)
        pointers = sorted(e["pointer"] for e in problem["errors"])
        self.assertEqual(pointers, ["/constraints/0/fix/1", "/materials/soft/density",
                                    "/parts/2", "/time/dt"], problem)

    def test_two_shapes_in_one_part(self):
        case = tiny_case("two")
        case["parts"][0]["disc"] = {"center": [0, 0], "radius": 0.05, "divisions": 16}
        self.post(case, 422, "/parts/0")

    def test_strings_for_numbers(self):
        self.post(edit(["materials", "rock", "young"], "3e10"), 422, "/materials/rock/young")
        self.post(edit(["time", "end"], "soon"), 422, "/time/end")

    def test_several_problems_reported_together(self):
        case = tiny_case("many")
        case["materials"]["rock"]["poisson"] = 0.7
        case["parts"][0]["material"] = "granit"
        problem = self.post(case, 422)
        self.assertGreaterEqual(len(problem["errors"]), 2)

    def test_garbage_gmsh(self):
        case = tiny_case("gmsh")
        del case["parts"][0]["rectangle"]
        case["parts"][0]["gmsh"] = "$MeshFormat\nthis is not a mesh\n$EndMeshFormat\n\x01\x02"
        self.post(case, 422, "/parts/0")

    def test_initial_stress(self):
        def stressed(block, dimension=2):
            if dimension == 3:
                case = tiny_case("stress3d", dimension=3)
                case["parts"][0] = {"name": "block", "material": "rock",
                                    "box": {"origin": [0, 0, 0], "size": [0.1, 0.1, 0.1],
                                            "divisions": [2, 2, 2]}}
                case["constraints"] = [{"box": [-1, -1, -0.001, 1, 1, 0.001], "fix": ["x", "y", "z"]}]
            else:
                case = tiny_case("stress")
            case["parts"][0]["initial_stress"] = block
            return case
        at = "/parts/0/initial_stress"
        self.post(stressed({"value": [-1e6, -2e6]}), 422, at + "/value", ["[sxx, syy, sxy]"])
        self.post(stressed({"value": [-1e6, -2e6, 0]}, 3), 422, at + "/value",
                  ["[sxx, syy, szz, syz, sxz, sxy]"])
        self.post(stressed({"value": [-1e6, "big", 0]}), 422, at + "/value/1", ["number"])
        self.post(stressed({"value": [-1e6, -2e6, None]}), 422, at + "/value/2")
        self.post(stressed({"value": [0, 0, 0], "gradient": [0, 2.7e4]}), 422, at + "/gradient")
        self.post(stressed({"value": [0, 0, 0], "gradient": [0, 2.7e4, 0]}), 422, at + "/gradient",
                  ["reference"])
        self.post(stressed({"value": [0, 0, 0], "reference": "top"}), 422, at + "/reference")
        self.post(stressed({"value": [0, 0, 0], "gradiant": [0, 1, 0], "reference": 0}), 422,
                  at + "/gradiant", ["gradient"])
        self.post(stressed({"gradient": [0, 1, 0], "reference": 0}), 422, at, ["value"])
        self.post(stressed([-1e6, -2e6, 0]), 422, at, ["object"])
        # non-finite numbers never reach the case: the JSON parser refuses them
        text = json.dumps(stressed({"value": [-1e6, -2e6, 0]})).replace("-2000000.0", "NaN")
        self.assertIn("NaN", text)
        self.post(text.encode(), 400)
        text = json.dumps(stressed({"value": [-1e6, -2e6, 0]})).replace("-2000000.0", "-1e999")
        self.assertIn("1e999", text)
        self.post(text.encode(), 400)

    def with_constraint(self, constraint, **top):
        case = tiny_case("loads", **top)
        case["constraints"].append(constraint)
        return case

    def test_bad_amplitudes(self):
        side = [-1, 0.099, 1, 1]  # the block's top edge
        for table, pointer in [(3, "/constraints/1/amplitude"),
                               ([], "/constraints/1/amplitude"),
                               ([[0, 0, 1]], "/constraints/1/amplitude/0"),
                               ([[0, 0], 5], "/constraints/1/amplitude/1"),
                               ([[0, "x"]], "/constraints/1/amplitude/0/1"),
                               ([[0, 0], [0, 1]], "/constraints/1/amplitude/1/0"),
                               ([[0, 0], [1, 1], [0.5, 1]], "/constraints/1/amplitude/2/0")]:
            for action in ({"force": [0, -1e3]}, {"pressure": 1e5}, {"velocity": [0, -1]}):
                self.post(self.with_constraint(dict(box=side, amplitude=table, **action)), 422,
                          pointer)
        problem = self.post(self.with_constraint({"box": side, "fix": ["x"], "amplitude": [[0, 1]]}),
                            422, "/constraints/1/amplitude")
        self.assertIn("fix", json.dumps(problem))
        self.post(self.with_constraint({"box": side, "absorb": True, "amplitude": [[0, 1]]}),
                  422, "/constraints/1/amplitude")
        self.post(tiny_case("g", gravity=[0, -9.81], gravity_amplitude=[[1, 0], [0, 1]]), 422,
                  "/gravity_amplitude/1/0")
        self.post(tiny_case("g", gravity=[0, -9.81], gravity_amplitude={"t": 1}), 422,
                  "/gravity_amplitude")

    def test_bad_pressure_and_absorb(self):
        side = [-1, 0.099, 1, 1]
        self.post(self.with_constraint({"box": side, "fix": ["x"], "pressure": 1e5}), 422,
                  "/constraints/1", words=["exactly one"])
        self.post(self.with_constraint({"box": side, "pressure": "high"}), 422,
                  "/constraints/1/pressure")
        self.post(self.with_constraint({"box": side, "pressure": [1e5, 0]}), 422,
                  "/constraints/1/pressure")
        self.post(self.with_constraint({"box": side, "absorb": 1}), 422, "/constraints/1/absorb")
        self.post(self.with_constraint({"box": side, "absorb": "yes"}), 422,
                  "/constraints/1/absorb")
        self.post(self.with_constraint({"box": side, "absorb": False}), 422,
                  "/constraints/1/absorb")
        self.post(self.with_constraint({"box": side, "absorb": True, "pressure": 1}), 422,
                  "/constraints/1")
        # one interior node: no boundary edge has all its nodes selected
        inner = [0.049, 0.049, 0.051, 0.051]
        for action in ({"pressure": 1e5}, {"absorb": True}):
            self.post(self.with_constraint(dict(box=inner, **action)), 422, "/constraints/1",
                      words=["boundary edge"])

    def test_dt_above_stable(self):
        problem = self.post(edit(["time", "dt"], 1.0), 422, "/time/dt")
        self.assertIn("stable", json.dumps(problem).lower())

    # ------------------------------------------------- 413, 411, paths
    def test_100mb_body_refused_before_sending(self):
        conn = self.d.connection(timeout=10)
        conn.putrequest("POST", "/cases")
        conn.putheader("Content-Type", "application/json")
        conn.putheader("Content-Length", "100000000")
        conn.endheaders()  # headers only: the body is never sent
        resp = conn.getresponse()
        data = resp.read()
        conn.close()
        headers = {k.lower(): v for k, v in resp.getheaders()}
        self.assertProblem(resp.status, headers, data, 413, words=["max-upload"])

    def test_body_over_limit_while_sending(self):
        body = b'{"name": "' + b"x" * (2 << 20) + b'"}'
        try:
            status, headers, data = self.d.request("POST", "/cases", body)
        except (BrokenPipeError, ConnectionResetError):
            return  # refused before we finished sending: also fine
        self.assertProblem(status, headers, data, 413)

    def test_chunked_body_needs_length(self):
        conn = self.d.connection(timeout=10)
        conn.putrequest("POST", "/cases")
        conn.putheader("Transfer-Encoding", "chunked")
        conn.endheaders()
        conn.send(b"2\r\n{}\r\n0\r\n\r\n")
        resp = conn.getresponse()
        data = resp.read()
        conn.close()
        self.assertProblem(resp.status, {k.lower(): v for k, v in resp.getheaders()}, data, 411)

    def test_missing_content_length(self):
        with socket.create_connection(("127.0.0.1", self.d.port), timeout=10) as s:
            s.sendall(b"POST /cases HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
            reply = b""
            while True:
                chunk = s.recv(65536)
                if not chunk:
                    break
                reply += chunk
        self.assertTrue(reply.startswith(b"HTTP/1.1 411"), reply[:100])
        self.assertIn(b"application/problem+json", reply)

    def test_path_traversal(self):
        for path in ("/cases/..%2F..%2Fetc", "/cases/../x", "/cases/..", "/cases/%2e%2e/case",
                     "/cases/../../etc/passwd", "/cases/..%2F" + self.kept["id"] + "/case",
                     "/cases/" + self.kept["id"] + "/..%2Fcase.json", "/cases/" + self.kept["id"] + "/../../x",
                     "//cases", "/cases//" + self.kept["id"], "/cases/" + self.kept["id"] + "%00"):
            status, headers, data = self.d.request("GET", path)
            self.assertEqual(status, 404, path)
            self.assertEqual(json.loads(data)["status"], 404)

    def test_bad_query(self):
        status, headers, data = self.d.request("POST", "/cases?start=maybe", tiny_case("q"))
        self.assertProblem(status, headers, data, 400, words=["start"])


if __name__ == "__main__":
    unittest.main()
