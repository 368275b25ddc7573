/*
 * state_json.h - engine state as the JSON of GET /cases/ID/state.
 *
 * Contract: {"step", "time", "<field>": ...} with position/velocity as
 * [[x, y], ...] per node ([[x, y, z], ...] in 3D), stress as
 * [[sxx, syy, sxy], ...] per element ([[sxx, syy, szz, syz, sxz, sxy], ...]
 * in 3D) and damage as a number per joint; only the fields present in the
 * snapshot; strain like stress, principal_stress as `dimension` numbers per
 * element, descending, and displacement (position - initial position) like
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

/* GET /cases/ID/fragments (contract 5.4): {"step", "time", "fragments":
 * [{"id", "elements", "mass", "size", "diameter", "centroid", "velocity"},
 * ...], "distribution": [{"diameter", "passing"}, ...]} of a snapshot taken
 * with SNAPSHOT_FRAGMENTS; NULL without them or when out of memory. */
json_t *fragments_to_json(const snapshot *s);

#endif
