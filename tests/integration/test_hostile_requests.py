"""Hostile requests (issue 11, contract 5.5): a case document built to make
validation expensive, slow clients that hold connections, and malformed
framing headers. Each must end with a prompt, clean answer while other
clients keep being served. Raw sockets are used where http.client would
refuse to send what a hostile client sends."""
import json
import random
import socket
import threading
import time
import unittest

from fdemd_harness import SLOW, DaemonTestCase


def unknown_material_case(parts=1024, materials=1500, seed=11):
    """Every part names an unknown 64-character material among 1500 other
    64-character ones: the worst case for a 'did you mean' search that
    compares every pair (~6e9 edit-distance cells, tens of seconds)."""
    rnd = random.Random(seed)
    letters = "abcdefghijklmnopqrstuvwxyz0123456789"

    def word():
        return "".join(rnd.choice(letters) for _ in range(64))

    return {
        "materials": {word(): {"density": 2700, "young": 3e10, "poisson": 0.25}
                      for _ in range(materials)},
        "parts": [{"name": "p%d" % i, "material": word(),
                   "rectangle": {"size": [1, 1], "divisions": [1, 1]}} for i in range(parts)],
        "time": {"end": 0.001},
    }


class ExpensiveValidationTest(DaemonTestCase):
    def post_timed(self, body):
        t0 = time.monotonic()
        status, headers, data = self.d.request("POST", "/cases", body,
                                               headers={"Content-Type": "application/json"})
        return status, json.loads(data), time.monotonic() - t0

    def test_unknown_names_are_checked_in_bounded_time(self):
        body = json.dumps(unknown_material_case()).encode()
        self.assertGreater(len(body), 300 << 10)
        status, problem, seconds = self.post_timed(body)
        self.assertEqual(status, 422)
        self.assertLess(seconds, 1.5 * SLOW, "validation took %.1f s" % seconds)
        self.assertIn("1024 problems", problem["detail"])
        self.assertIn("first 100 are listed", problem["detail"])
        self.assertEqual(len(problem["errors"]), 100)
        self.assertEqual(problem["errors"][0]["pointer"], "/parts/0/material")
        self.assertIn("unknown material", problem["errors"][0]["message"])

    def test_a_typo_still_gets_its_suggestion(self):
        case = unknown_material_case(parts=2, materials=3)
        case["materials"]["granite"] = {"density": 2700, "young": 3e10, "poisson": 0.25}
        case["parts"][1]["material"] = "granit"
        status, problem, _ = self.post_timed(json.dumps(case).encode())
        self.assertEqual(status, 422)
        messages = {e["pointer"]: e["message"] for e in problem["errors"]}
        self.assertIn('did you mean "granite"', messages["/parts/1/material"])

    def test_health_answers_while_several_are_checked(self):
        body = json.dumps(unknown_material_case()).encode()
        answers = []

        def post():
            try:
                answers.append(self.post_timed(body)[0])
            except OSError as e:  # a timeout is a failure, reported below
                answers.append(repr(e))

        threads = [threading.Thread(target=post) for _ in range(8)]
        for t in threads:
            t.start()
        t0 = time.monotonic()
        status, _, _ = self.d.request("GET", "/health")
        health_seconds = time.monotonic() - t0
        for t in threads:
            t.join(60 * SLOW)
        self.assertEqual(status, 200)
        self.assertLess(health_seconds, 1.0 * SLOW, "/health took %.1f s" % health_seconds)
        self.assertEqual(answers, [422] * 8)


if __name__ == "__main__":
    unittest.main()
