/*
 * registry_internal.h - what registry.c, case_record.c, registry_create.c,
 * case_status.c, registry_load.c and case_continue.c share, and nothing else
 * includes:
 * building a case record, its state names, the status object's durable
 * write, admitting a stored case, and loading one.
 */
#ifndef FDEMD_REGISTRY_INTERNAL_H
#define FDEMD_REGISTRY_INTERNAL_H

#include <jansson.h>

#include "common/config.h"
#include "registry.h"

server_case *case_new(void);
/* registry_create.c's last step: the stored case joins the list and starts
 * (or queues) when `start`, its `cost` moved from `lease` to its reserve.
 * -1 when the list cannot grow (the case is not listed). */
int registry_admit(server_case *c, int start, membudget_lease *lease, size_t cost);
int case_state_is_terminal(case_state s);
/* Figures of the case's model into its published figures. */
void case_publish_from_model(server_case *c);

/* case_warnings.c: the case's "warnings" (contract 6.2), each kept once
 * (pointer and message), at most 100; a JSON copy for the status; read
 * back from status.json's "warnings"; a problem list as such an array. */
void case_add_warning(server_case *c, const char *pointer, const char *message);
void case_add_warnings(server_case *c, const problems *w);
json_t *case_warnings_json(server_case *c);
void case_warnings_from_json(server_case *c, const json_t *list);
json_t *problems_warnings_json(const problems *w);

/* case_status.c: the status object as it would be in another state (to
 * make that state durable before it is shown), and its atomic write to
 * status.json (0, or -1 with the reason). */
json_t *case_status_json_as(server_case *c, case_state state, const char *error);
int case_write_status_json(server_case *c, json_t *o, char *reason, size_t reason_size);
/* Writes status.json as it will be in `state` (a terminal one with its
 * finished_at, also copied to `ended`) while the case still shows its
 * current state: the caller switches only once this returned 0, so no
 * client sees a state a crash would turn back. -1 as case_persist_status
 * (a case no worker runs is then failed with the write error). */
int case_persist_status_as(server_case *c, case_state state, char *ended, size_t ended_size);

/* registry_load.c: a stored case (a reference), or NULL when the directory
 * holds no acknowledged case. */
server_case *registry_load_case(const fdemd_config *cfg, const char *id);
void registry_sweep_half_made(const fdemd_config *cfg, const char *name);
/* Stops the background check and waits for it (registry_shutdown). */
void registry_stop_checks(void);

#endif
