"""fdemd_client - a Python client for the fdemd simulation daemon.

Standard library only (urllib.request, json), so it runs wherever Python 3
does. It speaks the HTTP API documented in docs/api.md of the fdemd
repository (routes, the status object, states, errors)::

    from fdemd_client import Client, FdemdError

    c = Client()                       # FDEMD_URL / FDEMD_TOKEN, else localhost:8080
    case_id = c.submit("examples/collision.json", start=True)
    final = c.wait(case_id, callback=lambda s: print(s["progress"]))
    h5, xdmf = c.fetch(case_id, "collision.h5")   # force=True to replace

Every refusal of the server raises FdemdError carrying the problem details
(status, title, detail and the list of {"pointer", "message"} errors), so a
script can show the user exactly where their case document is wrong.
"""

import json
import os
import re
import time
import urllib.error
import warnings
import urllib.parse
import urllib.request

__all__ = ["Client", "FdemdError", "FdemdConnectionError", "AmbiguousIdError", "DEFAULT_URL",
           "stage_label"]

DEFAULT_URL = "http://127.0.0.1:8080"
TERMINAL_STATES = ("finished", "failed", "stopped")

# The server's result.xdmf names its data "result.h5:/path"; a saved copy
# must name the .h5 file it was saved beside (see Client.fetch).
_XDMF_H5_REFERENCE = re.compile(r"""[^\s<>"']*result\.h5(?=:)""")


class FdemdError(Exception):
    """A request the server refused (or a case that ended badly).

    Attributes:
        status: the HTTP status (0 when the server could not be reached,
            None for a case that failed or was stopped, see Client.wait).
        title, detail: the problem details' title and detail.
        errors: list of {"pointer": JSON Pointer, "message": str}.
        case_status: for a failed/stopped case, its final status object.
    """

    def __init__(self, status, title, detail="", errors=None, case_status=None):
        self.status = status
        self.title = title
        self.detail = detail or ""
        self.errors = list(errors or [])
        self.case_status = case_status
        super().__init__(str(self))

    def __str__(self):
        head = self.title if self.status is None else "%s (HTTP %s)" % (self.title, self.status)
        lines = [head]
        if self.detail:
            lines.append("  " + self.detail)
        for e in self.errors:
            lines.append("  %s: %s" % (e.get("pointer") or "(document)", e.get("message", "")))
        return "\n".join(lines)


class FdemdConnectionError(FdemdError, ConnectionError):
    """The server could not be reached at all (status 0)."""


class AmbiguousIdError(ValueError):
    """A shortened case id that several cases' ids start with
    (Client.resolve_id); .prefix and .matches (the whole ids)."""

    def __init__(self, prefix, matches):
        self.prefix = prefix
        self.matches = list(matches)
        super().__init__("case id prefix %r is ambiguous: %d cases start with it (%s)"
                         % (prefix, len(self.matches), ", ".join(self.matches[:10])))


class Client:
    """A connection to one fdemd server.

    Args:
        url: base URL; default the FDEMD_URL environment variable, else
            http://127.0.0.1:8080.
        token: bearer token; default FDEMD_TOKEN (needed when the daemon was
            started with --token).
        timeout: seconds to wait for any single request.
    """

    def __init__(self, url=None, token=None, timeout=60.0):
        self.url = (url or os.environ.get("FDEMD_URL") or DEFAULT_URL).rstrip("/")
        self.token = token if token is not None else (os.environ.get("FDEMD_TOKEN") or None)
        self.timeout = timeout

    # ----------------------------------------------------------- transport

    def _open(self, method, path, body=None, content_type="application/json"):
        """Sends one request; returns the open response or raises FdemdError."""
        headers = {"Accept": "application/json, application/problem+json, */*"}
        if body is not None:
            headers["Content-Type"] = content_type
        if self.token:
            headers["Authorization"] = "Bearer " + self.token
        if method == "POST" and body is None:
            body = b""  # an explicit Content-Length: 0 (the server wants a length)
        request = urllib.request.Request(self.url + path, data=body, method=method,
                                         headers=headers)
        try:
            return urllib.request.urlopen(request, timeout=self.timeout)
        except urllib.error.HTTPError as e:
            raise _problem_from(e.code, e.read()) from None
        except (urllib.error.URLError, OSError) as e:
            reason = getattr(e, "reason", e)
            raise FdemdConnectionError(
                0, "Cannot reach fdemd",
                "could not reach the fdemd server at %s%s (%s); is it running?"
                % (self.url, path, reason)) from None

    def _json(self, method, path, body=None, content_type="application/json"):
        """Request whose answer is JSON (None for 204)."""
        with self._open(method, path, body, content_type) as response:
            data = response.read()
            if response.status == 204 or not data:
                return None
            return json.loads(data)

    @staticmethod
    def _case_path(case_id, suffix=""):
        return "/cases/" + urllib.parse.quote(str(case_id), safe="") + suffix

    # ------------------------------------------------------------- the API

    def health(self):
        """GET /health: {"status": "ok", "version", "cases", "running"}."""
        return self._json("GET", "/health")

    def submit(self, case, start=False):
        """Uploads a case and returns its id.

        Args:
            case: a dict (the case document), bytes (its JSON text), or the
                path of a JSON file.
            start: also start it (POST /cases?start=true).
        Raises:
            FdemdError: 422 with one error per problem for an invalid case,
                400 for malformed JSON.
        Warns:
            UserWarning: the server's warning for a case that will run for
                hours (the case is stored all the same).
        """
        body = _case_body(case)
        path = "/cases?start=true" if start else "/cases"
        status = self._json("POST", path, body)
        if status.get("warning"):
            warnings.warn("case %s: %s" % (status["id"], status["warning"]), stacklevel=2)
        return status["id"]

    def dry_run(self, case):
        """Checks and sizes a case without storing it (POST /cases?dry_run=true).

        Args:
            case: as for submit().
        Returns:
            {"nodes", "elements", "joints", "dt", "steps", "snapshots",
            "memory_bytes", "result_bytes", "estimated_seconds",
            "warnings"} ([{"pointer", "message"}], values far outside rock
            and steel), plus "warning" when the case would run for hours.
        Raises:
            FdemdError: as submit() does for an invalid case.
        """
        return self._json("POST", "/cases?dry_run=true", _case_body(case))

    def list(self, state=None):
        """The cases' status objects, oldest first; only those in `state`
        ("created", "queued", "running", "paused", "finished", "stopped" or
        "failed") when given."""
        path = "/cases"
        if state is not None:
            path += "?state=" + urllib.parse.quote(str(state), safe="")
        return self._json("GET", path)["cases"]

    def resolve_id(self, prefix):
        """The whole id of the one case whose id starts with `prefix`, as
        fdemctl resolves a shortened ID (one GET /cases): a whole id, or a
        prefix no case has, comes back as given (the next request then gets
        the server's 404). Raises ValueError for an empty prefix and
        AmbiguousIdError (a ValueError, with .matches: the ids) when several
        cases start with it."""
        prefix = str(prefix)
        if not prefix:
            raise ValueError("an empty case id names no case")
        ids = [c.get("id", "") for c in self.list()]
        if prefix in ids:
            return prefix
        matches = [i for i in ids if i.startswith(prefix)]
        if len(matches) > 1:
            raise AmbiguousIdError(prefix, matches)
        return matches[0] if matches else prefix

    def status(self, case_id):
        """The status object of one case (state, step, time, progress,
        stage, ...); "stage" is {"index", "name"} of the stage the case is
        in, None for a case without "stages" (see stage_label)."""
        return self._json("GET", self._case_path(case_id))

    def warnings(self, case_id):
        """The case's warnings (docs/api.md, the status object): a list
        of {"pointer", "message"}: values of its document far outside rock
        and steel (a unit typed wrong), and what its run saw (elements
        passing into one another, with the step and the two elements).
        Never a refusal."""
        return self.status(case_id).get("warnings", [])

    def stage(self, case_id):
        """(index, name) of the stage the case is in, None for a case
        without "stages" (docs/case-format.md, "Stages and excavation")."""
        s = self.status(case_id).get("stage")
        return None if s is None else (s["index"], s["name"])

    def start(self, case_id):
        """created or paused -> running; returns the status."""
        return self._json("POST", self._case_path(case_id, "/start"))

    def pause(self, case_id):
        """running -> paused at the next step boundary; returns the status."""
        return self._json("POST", self._case_path(case_id, "/pause"))

    def stop(self, case_id):
        """Any non-terminal state -> stopped (results kept); returns the status."""
        return self._json("POST", self._case_path(case_id, "/stop"))

    def delete(self, case_id):
        """Stops the case if needed and removes it and its files."""
        self._json("DELETE", self._case_path(case_id))

    def extend(self, case_id, end, start=False):
        """Runs a finished or paused case on to the later end time `end`
        (POST /cases/ID/extend): the case becomes paused with the new end and
        its results go on in the same result.h5 once started. Returns the
        status (after the start, with start=True).

        Raises:
            FdemdError: 409 when the case is not finished or paused, or when
                `end` is not beyond its current end; 422 for an end that is
                not a finite number.
        """
        status = self._json("POST", self._case_path(case_id, "/extend"),
                            json.dumps({"end": end}).encode("utf-8"))
        return self.start(case_id) if start else status

    def clone(self, case_id, patch, start=False, dry_run=False):
        """Creates a new case from the stored document of `case_id` with
        `patch` applied, and returns its id (POST /cases/ID/clone).

        The patch is a JSON Merge Patch (RFC 7396) when it is an object: an
        object merges, None (null) removes a member, anything else replaces
        it, e.g. ``{"name": "softer", "materials": {"rock": {"young":
        1e9}}}``. It is a JSON Patch (RFC 6902) when it is a list of
        operations, sent as application/json-patch+json: it changes one
        element of an array without resending the array (a mesh), e.g.
        ``[{"op": "replace", "path": "/parts/0/material", "value":
        "granite"}, {"op": "test", "path": "/constraints/1/velocity/0",
        "value": -0.1}]``; it is atomic (a failing operation, a failed
        "test" included, creates nothing).

        Args:
            patch: a dict or list, bytes (its JSON text) or the path of a
                JSON file (a text whose first character is "[" is a JSON
                Patch).
            start: also start the new case.
            dry_run: create nothing; return what the clone would be: the
                sizing object of dry_run() (nodes, steps, memory_bytes,
                estimated_seconds, ...), or the FdemdError its validation
                gives.
        Raises:
            FdemdError: as submit() does, with pointers into the patched
                document; 422 at "/i" for JSON Patch operation i that fails;
                404 when `case_id` does not exist.
        """
        if start and dry_run:
            raise ValueError("a dry run creates nothing, so it cannot start")
        body = json.dumps(patch).encode("utf-8") if isinstance(patch, list) else _case_body(patch)
        json_patch = body.lstrip()[:1] == b"["
        query = "?dry_run=true" if dry_run else "?start=true" if start else ""
        status = self._json("POST", self._case_path(case_id, "/clone" + query), body,
                            "application/json-patch+json" if json_patch else "application/json")
        if dry_run:
            return status
        if status.get("warning"):
            warnings.warn("case %s: %s" % (status["id"], status["warning"]), stacklevel=2)
        return status["id"]

    def case(self, case_id):
        """The case document as stored (as uploaded; an extend rewrites
        its time.end), parsed."""
        return self._json("GET", self._case_path(case_id, "/case"))

    def state(self, case_id, fields=None):
        """The current state, taken at one step boundary.

        Args:
            fields: names among "position", "velocity", "stress", "damage",
                "strain", "principal_stress", "displacement" (a list or a
                comma-separated string); None = server default.
        Returns:
            {"step", "time", <field>: ...}: position/velocity/displacement
            [[x, y], ...] per node ([[x, y, z], ...] in 3D; displacement is
            position - initial position), stress and strain [[xx, yy,
            xy], ...] per element (3D: xx, yy, zz, yz, xz, xy; strain is
            Green-Lagrange), principal_stress [[s1, s2], ...] (3D: three)
            descending with tension positive, so the last column is the
            most compressive, sigma1 of rock mechanics (the answer's
            "principal_stress_names" is ["sigma3", "sigma1"], 3D
            ["sigma3", "sigma2", "sigma1"]), damage per joint;
            docs/api.md, "GET /cases/ID/state". A case with stages also
            has "stage" {"index", "name"} and "active": one flag a
            element, 1 still there, 0 excavated.
        """
        suffix = "/state"
        if fields:
            if not isinstance(fields, str):
                fields = ",".join(fields)
            suffix += "?fields=" + urllib.parse.quote(fields, safe=",")
        return self._json("GET", self._case_path(case_id, suffix))

    def fragments(self, case_id, parts=None, exclude_host=False):
        """The pieces the case has broken into, at one step boundary.

        Args:
            parts: only the fragments of these parts (names, a list or a
                comma-separated string); None: every part.
            exclude_host: leave out the host body: every fragment that a
                fix or velocity constraint holds (a fixed slope, a
                supported rock mass, a platen) and the fragment holding
                more than half the model's mass (the rock around an
                excavation); their ids are in "host".
        Returns:
            {"step", "time", "fragments": [{"id", "elements", "mass", "size",
            "diameter", "centroid", "velocity", "part", "held"}, ...],
            "distribution": [{"diameter", "passing"}, ...]} (and "host"
            with exclude_host): size is the area (2D, mass per metre of
            thickness) or volume (3D), diameter that of the circle or
            sphere of that size, part the index in the case's parts, held
            whether a constraint holds it, and distribution the sieve curve
            of the fragments listed (mass fraction of them no larger than
            each diameter).
        """
        query = []
        if parts is not None:
            if not isinstance(parts, str):
                parts = ",".join(parts)
            query.append("parts=" + urllib.parse.quote(parts, safe=","))
        if exclude_host:
            query.append("exclude_host=true")
        suffix = "/fragments" + ("?" + "&".join(query) if query else "")
        return self._json("GET", self._case_path(case_id, suffix))

    def events(self, case_id, since=None):
        """The fracture events of the case: one per joint that broke, in the
        order they broke (docs/api.md, "GET /cases/ID/events").

        Args:
            since: a time in seconds; only the events after it (time >
                since) are returned, so passing the last time seen gives
                only the new ones. None: all.
        Returns:
            {"dimension", "since", "count", "events": [{"time", "joint",
            "position", "mode", "energy"}, ...]}: time the end of the step
            the joint broke in, position its midpoint ([x, y] or [x, y,
            z]), mode 1 tensile, 2 shear, 3 mixed, energy what it
            dissipated (J per metre in 2D). The same rows as /events/* in
            result.h5.
        """
        suffix = "/events"
        if since is not None:
            suffix += "?since=" + repr(float(since))
        return self._json("GET", self._case_path(case_id, suffix))

    def history(self, case_id, since=0):
        """The history rows of the case (docs/api.md, "GET
        /cases/ID/history"): one per history interval (or per snapshot for a
        case without "history"), those with time > since: the default 0
        leaves out the row at t = 0, None gives every row.

        Returns:
            {"names": [point names], "rows": [{"time", "step", "points":
            {"displacement", "velocity"} (one vector per point),
            "constraint_force", "constraint_displacement" (one vector per
            constraint: its force and the mean displacement of its nodes),
            "energy": {account: J}}, ...]}, plain lists (no numpy needed).
            history_columns() turns it into columns, numpy arrays where
            numpy exists.
        """
        suffix = "/history"
        if since is not None:
            suffix += "?since=" + repr(float(since))
        return self._json("GET", self._case_path(case_id, suffix))

    @staticmethod
    def history_columns(history):
        """Columns of a history() answer: {"time" (H), "step" (H),
        "point_displacement" and "point_velocity" (H, P, dim),
        "constraint_force" and "constraint_displacement" (H, C, dim),
        "energy": {account: (H)}, "names"}, and with fluid "source_pressure"
        and "injected_volume" (H, C; None/NaN for a constraint that does
        not inject): numpy arrays where numpy exists, else nested lists."""
        rows = history["rows"]
        columns = {
            "names": list(history.get("names", [])),
            "time": [r["time"] for r in rows],
            "step": [r["step"] for r in rows],
            "point_displacement": [r["points"]["displacement"] for r in rows],
            "point_velocity": [r["points"]["velocity"] for r in rows],
            "constraint_force": [r["constraint_force"] for r in rows],
            "constraint_displacement": [r["constraint_displacement"] for r in rows],
            "energy": {k: [r["energy"][k] for r in rows]
                       for k in (rows[0]["energy"] if rows else {})},
        }
        fluid = [k for k in ("source_pressure", "injected_volume") if rows and "fluid" in rows[0]]
        for key in fluid:
            columns[key] = [r["fluid"][key] for r in rows]
        try:
            import numpy as np
        except ImportError:
            return columns
        for key in ("time", "step", "point_displacement", "point_velocity",
                    "constraint_force", "constraint_displacement") + tuple(fluid):
            columns[key] = np.asarray(columns[key], dtype=float if key != "step" else int)
        columns["energy"] = {k: np.asarray(v, dtype=float) for k, v in columns["energy"].items()}
        return columns

    def stream(self, case_id=None, last_event_id=None, read_timeout=45.0):
        """Follows the daemon's event stream (GET /stream, Server-Sent Events).

        The stream is open when this returns (raising FdemdError when the
        daemon refuses one: 404 from a daemon without streams, 503 when
        --max-streams are open): an iterator of (kind, data, event_id), one
        per event as it arrives. kind is "status" (data: a status object,
        as status() gives), "snapshot" ({"id", "index", "time"}: snapshot
        `index` of the case is written) or "deleted" ({"id"}); event_id is
        the event's id (a string). Given back as last_event_id, it resumes
        the stream right after that event, with nothing lost if it is among
        the daemon's last 1000. case_id narrows the stream to one case. The
        iterator ends when the daemon ends the stream (it stops), and
        raises TimeoutError when nothing arrives for read_timeout seconds
        (the daemon sends a keep-alive every 15 s).
        """
        response = self._open_stream(case_id, last_event_id, read_timeout)
        return _closing_events(response)

    def _open_stream(self, case_id, last_event_id, read_timeout):
        headers = {"Accept": "text/event-stream"}
        if self.token:
            headers["Authorization"] = "Bearer " + self.token
        if last_event_id is not None:
            headers["Last-Event-ID"] = str(last_event_id)
        path = "/stream" + ("?case=" + urllib.parse.quote(str(case_id), safe="")
                            if case_id is not None else "")
        request = urllib.request.Request(self.url + path, headers=headers)
        try:
            return urllib.request.urlopen(request, timeout=read_timeout)
        except urllib.error.HTTPError as e:
            raise _problem_from(e.code, e.read()) from None
        except (urllib.error.URLError, OSError) as e:
            raise FdemdConnectionError(
                0, "Cannot reach fdemd", "could not reach the fdemd server at %s%s (%s)"
                % (self.url, path, getattr(e, "reason", e))) from None

    def wait(self, case_id, callback=None, interval=0.5, raise_on_failure=False, timeout=None):
        """Waits until the case is finished, failed or stopped.

        It follows the daemon's event stream (stream()), so each status is
        seen as the daemon sends it and an end at once; when the daemon has
        no stream (an older one), refuses one, or the stream is cut, it
        polls GET /cases/ID instead.

        Args:
            callback: called with every status object seen (the last one
                included), e.g. to draw progress.
            interval: seconds between polls, when polling.
            raise_on_failure: raise FdemdError (status None, the case's
                error as detail, case_status set) when the case ends failed
                or stopped instead of returning its status.
            timeout: give up after this many seconds (raises TimeoutError).
        Returns:
            the final status object.
        """
        deadline = None if timeout is None else time.monotonic() + timeout
        last_state = [None]

        def seen(s):
            """Shows one status; True when the case has ended."""
            if callback is not None:
                callback(s)
            state = s.get("state")
            if state in ("created", "paused") and state != last_state[0]:
                # It will not move until someone starts it: keep waiting
                # (another client may), but say why, once per such state.
                warnings.warn("case %s is %s: it does not run until it is started "
                              "(Client.start(%r)); waiting" % (case_id, state, case_id),
                              stacklevel=3)
            last_state[0] = state
            return state in TERMINAL_STATES

        s = self.status(case_id)
        if not seen(s):
            s = self._follow(case_id, seen, deadline) or self._poll(case_id, seen, interval,
                                                                      deadline, timeout)
        if raise_on_failure and s["state"] != "finished":
            detail = s.get("error") or "stopped at step %s, t = %s s" % (s.get("step"), s.get("time"))
            raise FdemdError(None, "Case %s %s" % (case_id, s["state"]), detail, case_status=s)
        return s

    def _follow(self, case_id, seen, deadline):
        """The final status, followed on the event stream; None when there
        is no stream to follow (the caller polls)."""
        left = None if deadline is None else deadline - time.monotonic()
        read_timeout = 45.0 if left is None else max(0.1, min(45.0, left))
        try:
            response = self._open_stream(case_id, None, read_timeout)
        except FdemdError:
            return None
        with response:
            # the stream is open: what changed since the first look is read now
            s = self.status(case_id)
            if seen(s):
                return s
            try:
                for kind, data, _ in _read_events(response):
                    if kind == "status" and seen(data):
                        return data
                    if kind == "deleted":
                        self.status(case_id)  # raises its 404
                    if deadline is not None and time.monotonic() > deadline:
                        break  # the poll says it has timed out
            except (TimeoutError, OSError, ValueError):
                pass
        return None

    def _poll(self, case_id, seen, interval, deadline, timeout):
        while True:
            s = self.status(case_id)
            if seen(s):
                return s
            if deadline is not None and time.monotonic() > deadline:
                raise TimeoutError("case %s still %s after %g s" % (case_id, s.get("state"), timeout))
            time.sleep(interval)

    def fetch(self, case_id, path=None, force=False):
        """Downloads result.h5 to `path` and the XDMF sidecar beside it.

        The XDMF gets the same stem (``run.h5`` -> ``run.xdmf``) and its
        references to "result.h5" are rewritten to the saved file's name, so
        ParaView opens the .xdmf directly. Files are written to "<path>.part"
        first and renamed, so an interrupted download leaves no truncated
        result. Works while the case runs (every snapshot written so far).

        Args:
            path: where to save the .h5 (default "<name>.h5" with <name> the
                case's name, else "<id>.h5").
            force: replace the .h5 or .xdmf if it exists; without it an
                existing file is never overwritten.
        Returns:
            (h5_path, xdmf_path)
        Raises:
            FileExistsError: the .h5 or .xdmf exists and force is False
                (nothing is downloaded).
        """
        if path is None:
            name = self.status(case_id).get("name") or str(case_id)
            path = re.sub(r"[^A-Za-z0-9._-]", "_", name).lstrip(".") + ".h5"
        path = os.fspath(path)
        stem = re.sub(r"\.(h5|hdf5|hdf)$", "", path)
        xdmf_path = stem + ".xdmf"
        for existing in (path, xdmf_path):
            if not force and os.path.exists(existing):
                raise FileExistsError(
                    "%s exists; not overwriting it (pass force=True to replace it)" % existing)

        with self._open("GET", self._case_path(case_id, "/result.h5")) as response:
            _save_stream(response, path)
        with self._open("GET", self._case_path(case_id, "/result.xdmf")) as response:
            text = response.read().decode("utf-8")
        name = _xml_escape(os.path.basename(path))
        text = _XDMF_H5_REFERENCE.sub(lambda m: name, text)
        _save_bytes(text.encode("utf-8"), xdmf_path)
        return path, xdmf_path


# ---------------------------------------------------------------- helpers

def stage_label(status):
    """A status object's stage as text: 'stage 1 "excavate"', or "" for a
    case without stages; e.g. Client.wait(case_id, callback=lambda s:
    print(s["progress"], stage_label(s)))."""
    s = status.get("stage")
    return "" if not s else 'stage %d "%s"' % (s["index"], s["name"])


def _case_body(case):
    """The JSON text of a case given as a dict, bytes or a file path."""
    if isinstance(case, dict):
        return json.dumps(case).encode("utf-8")
    if isinstance(case, (bytes, bytearray)):
        return bytes(case)
    with open(case, "rb") as f:
        return f.read()


def _problem_from(status, body):
    """FdemdError from an error answer (problem details, or anything else)."""
    try:
        doc = json.loads(body)
    except ValueError:
        doc = None
    if isinstance(doc, dict) and ("title" in doc or "detail" in doc):
        return FdemdError(status, doc.get("title") or "Request refused",
                          doc.get("detail") or "", doc.get("errors") or [])
    text = body.decode("utf-8", "replace")[:300] if body else ""
    return FdemdError(status, "Request refused", text)


def _closing_events(response):
    with response:
        yield from _read_events(response)


def _read_events(response):
    """(kind, data, event_id) of each event of a text/event-stream body;
    comment lines (the opening line, keep-alives, a note that events were
    dropped) are skipped."""
    kind, data, event_id = None, [], None
    for raw in response:
        line = raw.decode("utf-8").rstrip("\r\n")
        if not line:
            if data:
                yield kind or "message", json.loads("\n".join(data)), event_id
            kind, data = None, []
            continue
        if line.startswith(":"):
            continue
        field, _, value = line.partition(":")
        value = value[1:] if value.startswith(" ") else value
        if field == "event":
            kind = value
        elif field == "data":
            data.append(value)
        elif field == "id":
            event_id = value


def _save_stream(response, path):
    part = path + ".part"
    try:
        with open(part, "wb") as f:
            while True:
                chunk = response.read(1 << 20)
                if not chunk:
                    break
                f.write(chunk)
        os.replace(part, path)
    finally:
        if os.path.exists(part):
            os.remove(part)


def _save_bytes(data, path):
    part = path + ".part"
    with open(part, "wb") as f:
        f.write(data)
    os.replace(part, path)


def _xml_escape(text):
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
