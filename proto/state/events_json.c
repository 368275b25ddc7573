/*
 * events_json.c - fracture events as the JSON body of GET
 * /cases/ID/events: one object per event with the names of the /events
 * datasets, so a script reads the route and the file alike. Reals go out
 * with 17 digits (jansson), the exact doubles of the file.
 */
#include "events_json.h"

static json_t *event_to_json(const fdem_event *e, int dimension)
{
    json_t *position = json_array();
    for (int d = 0; d < dimension && position; d++)
        if (json_array_append_new(position, json_real(e->position[d])) < 0) {
            json_decref(position);
            position = NULL;
        }
    if (!position) return NULL;
    return json_pack("{s:f, s:i, s:o, s:i, s:f}", "time", e->time, "joint", (int)e->joint,
                     "position", position, "mode", (int)e->mode, "energy", e->energy);
}

json_t *events_to_json(const fdem_event *events, int count, int dimension, const double *since)
{
    json_t *list = json_array();
    if (!list) return NULL;
    for (int i = 0; i < count; i++) {
        json_t *e = event_to_json(&events[i], dimension);
        if (!e || json_array_append_new(list, e) < 0) {
            json_decref(list);
            return NULL;
        }
    }
    return json_pack("{s:i, s:o, s:i, s:o}", "dimension", dimension, "since",
                     since ? json_real(*since) : json_null(), "count", count, "events", list);
}
