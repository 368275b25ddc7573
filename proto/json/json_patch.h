/*
 * json_patch.h - rewriting a stored case document: JSON Merge Patch
 * (RFC 7396) and JSON Patch (RFC 6902) for POST /cases/ID/clone, and a
 * dump that keeps every number exactly as it reads back (for the documents
 * extend and clone store).
 *
 * Contract:
 *  - json_merge_patch() returns a new reference: `target` with `patch`
 *    merged in (null deletes a member, objects merge recursively, any
 *    other value replaces). Neither argument is changed; NULL only when
 *    memory runs out. A `target` NULL is treated as absent (RFC 7396).
 *  - json_patch_apply() returns a new reference: `target` with the JSON
 *    Patch `patch` (an array of add, remove, replace, move, copy and test
 *    operations addressed by RFC 6901 pointers, "-" the end of an array)
 *    applied in order; neither argument is changed. It is atomic: NULL
 *    when any operation fails (a `test` that does not hold included), with
 *    the problems added to `p` (status 422): a patch that is not an array
 *    at "", each malformed operation at its pointer into the patch ("/2/op",
 *    "/2/path", "/2/value", all of them before any runs), or the first
 *    operation that fails at "/i" with why ("remove failed, so the patch
 *    changed nothing: path /parts/7 does not exist (/parts has 3
 *    elements)"). NULL with no problem added: out of memory. Numbers are
 *    compared by value in `test` (1 equals 1.0).
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

#include "problems.h"

json_t *json_merge_patch(const json_t *target, const json_t *patch);
json_t *json_patch_apply(const json_t *target, const json_t *patch, problems *p);
char *json_dump_document(const json_t *doc, size_t *length);
/* x with the fewest significant digits ("%.*g") that read back to x, for
 * numbers a person reads in a message (0.0004, not 0.00040000000000000002). */
void format_shortest_real(char *out, size_t size, double x);

#endif
