/*
 * state_json.h - engine state as the JSON of GET /cases/ID/state.
 *
 * Contract: {"step", "time", "<field>": ...} with position/velocity as
 * [[x, y], ...] per node ([[x, y, z], ...] in 3D), stress as
 * [[sxx, syy, sxy], ...] per element ([[sxx, syy, szz, syz, sxz, sxy], ...]
 * in 3D) and damage as a number per joint; only the fields present in the
 * snapshot; strain like stress, principal_stress as `dimension` numbers per
 * element, descending (tension positive), with "principal_stress_names"
 * ["sigma3", "sigma1"] (3D: ["sigma3", "sigma2", "sigma1"]), the name of
 * each column in rock mechanics' convention, where sigma1 is the most
 * compressive; and displacement (position - initial position) like
 * position. A case with stages (contract 6.1) always gets "active": one
 * flag a element, 1 still there, 0 excavated (whatever the fields), so a
 * client drawing the state can leave the excavated elements out; the
 * daemon adds "stage" to such a state (it knows the names).
 *
 * Folder: proto/state/ (its contract: snapshot.h).
 */
#ifndef FDEM_STATE_JSON_H
#define FDEM_STATE_JSON_H

#include <jansson.h>
#include "snapshot.h"

json_t *state_to_json(const snapshot *s);

/* Which fragments GET /cases/ID/fragments lists (issue 33 item 6): those
 * of the parts p with parts[p] != 0 (every part when `parts` is NULL),
 * and, with exclude_host, not the host body: a fragment is the host when
 * it is held (fdem_fragment.held: a fix or velocity constraint prescribes
 * the motion of one of its nodes: a fixed slope, a supported rock mass, a
 * driven platen) or holds more than half the mass of the whole model (the
 * rock mass around an excavation), whichever parts are listed. */
typedef struct fragment_selection {
    const unsigned char *parts;
    int part_count;
    int exclude_host;
} fragment_selection;

/* GET /cases/ID/fragments (contract 5.4): {"step", "time", "fragments":
 * [{"id", "elements", "mass", "size", "diameter", "centroid", "velocity",
 * "part", "held"}, ...], "distribution": [{"diameter", "passing"}, ...]}
 * of a snapshot taken with SNAPSHOT_FRAGMENTS; NULL without them or when
 * out of memory. Ids are those of /snapshots/fragment whatever is left
 * out; `part` is the index in the case's parts. With a selection (NULL:
 * every fragment) only the fragments it lists are in "fragments" and in
 * the sieve curve (which then reaches 1 over them), and with exclude_host
 * "host" lists the ids left out as the host. */
json_t *fragments_to_json(const snapshot *s, const fragment_selection *sel);

#endif
