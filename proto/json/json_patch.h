/*
 * json_patch.h - rewriting a stored case document: JSON Merge Patch
 * (RFC 7396) for POST /cases/ID/clone, and a dump that keeps every number
 * exactly as it reads back (for the documents extend and clone store).
 *
 * Contract:
 *  - json_merge_patch() returns a new reference: `target` with `patch`
 *    merged in (null deletes a member, objects merge recursively, any
 *    other value replaces). Neither argument is changed; NULL only when
 *    memory runs out. A `target` NULL is treated as absent (RFC 7396).
 *  - json_dump_document() is json_dumps(JSON_INDENT(2)) except that each
 *    real is written with the fewest digits that read back to the same
 *    double (jansson writes 17 digits: 0.1 becomes 0.10000000000000001),
 *    so a rewritten document reads like the uploaded one and gives the
 *    same numbers. The text comes from jansson's allocator (so a daemon
 *    that meters jansson meters it too) and is free()d when that allocator
 *    is malloc-based, as jansson's default and fdemd's meter are; NULL
 *    when memory runs out.
 *
 * Folder: proto/json/ (its contract: problems.h).
 */
#ifndef FDEM_JSON_PATCH_H
#define FDEM_JSON_PATCH_H

#include <jansson.h>

json_t *json_merge_patch(const json_t *target, const json_t *patch);
char *json_dump_document(const json_t *doc, size_t *length);
/* x with the fewest significant digits ("%.*g") that read back to x, for
 * numbers a person reads in a message (0.0004, not 0.00040000000000000002). */
void format_shortest_real(char *out, size_t size, double x);

#endif
