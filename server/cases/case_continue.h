/*
 * case_continue.h - a case continued (contract 5.3 "Continue and clone"):
 * POST /cases/ID/extend runs a finished or paused case on to a later end
 * in the same files; POST /cases/ID/clone makes a new case from a stored
 * one and a JSON Merge Patch (RFC 7396) or a JSON Patch (RFC 6902).
 *
 * Contract:
 *  - registry_extend(): body {"end": t}. 0 when the case is now paused with
 *    end t: case.json says time.end = t (and output.interval, when it was
 *    left to its default, is pinned to the interval the case ran with, so
 *    the snapshots go on at their pace), result.h5's root attribute `case`
 *    is the same document, status.json has end_time t. Else 400/422 with
 *    `p` (pointers into the body), 404, 409 (state, or t not beyond the
 *    current end) or 500 with a sentence in msg.
 *    The steps are made crash-atomic by one durable record written before
 *    any of them, DIR/ID/extend.json {"end": t}: once it is stored the
 *    extend is carried out, by this request or, after a crash between its
 *    writes, by registry_extend_recover() at start-up (every step can be
 *    redone); it is removed once status.json says paused with end t. An
 *    extend that failed half way (500) is completed by the next extend.
 *  - registry_extend_recover(): at start-up, a case loaded finished or
 *    paused with such a record is completed (paused, end t, all files
 *    agreeing); a step that fails again leaves the record for the next
 *    start-up and the case as loaded.
 *  - registry_clone_document(): the stored case.json of `c` with the patch
 *    merged in (RFC 7396), or with `json_patch` the JSON Patch (RFC 6902)
 *    applied, as text to give to registry_create() (which then validates
 *    it, with pointers into this patched document). NULL with *status 400
 *    (patch not JSON, in `p`), 422 (in `p`: a merge patch that is not an
 *    object, a JSON Patch that is not an array, has malformed operations
 *    or one that fails, a `test` included: json_patch_apply()), 404, 503
 *    (the work would pass --max-memory; it is metered against the
 *    request's lease) or 500 (err).
 */
#ifndef FDEMD_CASE_CONTINUE_H
#define FDEMD_CASE_CONTINUE_H

#include <stddef.h>

#include "registry.h"

int registry_extend(server_case *c, const char *body, size_t size, problems *p, char *msg,
                    size_t msglen);
void registry_extend_recover(server_case *c);
char *registry_clone_document(server_case *c, const char *body, size_t size, int json_patch,
                              size_t *length, problems *p, int *status, char *err, size_t errlen);

#endif
