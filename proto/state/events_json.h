/*
 * events_json.h - fracture events as the JSON of GET /cases/ID/events
 * (contract 5.4).
 *
 * Contract: {"dimension", "since", "count", "events": [{"time", "joint",
 * "position": [x, y(, z)], "mode", "energy"}, ...]} in the order of
 * /events (the order the joints broke); "since" is the filter's bound or
 * null. NULL when out of memory or a number is not finite.
 *
 * Folder: proto/state/ (its contract: snapshot.h).
 */
#ifndef FDEM_EVENTS_JSON_H
#define FDEM_EVENTS_JSON_H

#include <jansson.h>
#include "fdem.h"

json_t *events_to_json(const fdem_event *events, int count, int dimension, const double *since);

#endif
