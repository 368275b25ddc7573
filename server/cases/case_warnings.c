/*
 * case_warnings.c - a case's "warnings" (contract 6.2): what its document
 * holds that is far outside rock and steel (proto/case/case_warnings.c, at
 * submission) and what its run saw (elements passing into one another,
 * from the engine's fdem_take_penetration, added by the worker). Each is
 * kept once, in the order found, with the case under its `lock`; the
 * status object carries them, so status.json keeps them across a restart
 * (case_warnings_from_json reads them back).
 */
#include <string.h>

#include "registry.h"
#include "registry_internal.h"

static void warning_add_locked(server_case *c, const char *pointer, const char *message)
{
    if (!c->warnings) c->warnings = json_array();
    status_warning_add(c->warnings, pointer, message);
}

void case_add_warning(server_case *c, const char *pointer, const char *message)
{
    pthread_mutex_lock(&c->lock);
    warning_add_locked(c, pointer, message);
    pthread_mutex_unlock(&c->lock);
}

void case_add_warnings(server_case *c, const problems *w)
{
    for (int i = 0; i < w->count; i++)
        case_add_warning(c, w->items[i].pointer, w->items[i].message);
}

json_t *case_warnings_json(server_case *c)
{
    pthread_mutex_lock(&c->lock);
    json_t *copy = c->warnings ? json_deep_copy(c->warnings) : json_array();
    pthread_mutex_unlock(&c->lock);
    return copy ? copy : json_array();
}

void case_warnings_from_json(server_case *c, const json_t *list)
{
    size_t i;
    const json_t *w;
    json_array_foreach(list, i, w) {
        const char *pointer = json_string_value(json_object_get(w, "pointer"));
        const char *message = json_string_value(json_object_get(w, "message"));
        if (pointer && message) case_add_warning(c, pointer, message);
    }
}

json_t *problems_warnings_json(const problems *w)
{
    json_t *list = json_array();
    for (int i = 0; list && i < w->count; i++) {
        json_t *o = json_object();
        json_object_set_new(o, "pointer", json_string(w->items[i].pointer));
        json_object_set_new(o, "message", json_string(w->items[i].message));
        json_array_append_new(list, o);
    }
    return list;
}
