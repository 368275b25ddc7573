/*
 * fragment_query.h - the ?parts= of GET /cases/ID/fragments: part names
 * turned into the part indices a fragment_selection (state/state_json.h)
 * filters by (issue 33 item 6).
 *
 * Contract: fragment_query_parts() reads the names of the case's parts
 * from its stored case.json ("name", or "part<i>" for an unnamed part, as
 * /mesh/part_names of result.h5 says) and sets sel->parts (part_count
 * flags, 1 for each part named in the comma-separated `csv`). 0, or an
 * HTTP status with a sentence in detail: 400 (an empty list or a name
 * that is no part's; the sentence lists the names), 503 (parsing the
 * document would pass --max-memory now; jansson is metered) or 500 (the
 * document cannot be read). Parsing the document is heavy work: call it
 * on a heavy-work thread. fragment_query_free() frees sel->parts.
 */
#ifndef FDEMD_FRAGMENT_QUERY_H
#define FDEMD_FRAGMENT_QUERY_H

#include <stddef.h>

#include "cases/registry.h"
#include "state/state_json.h"

int fragment_query_parts(const server_case *c, const char *csv, fragment_selection *sel,
                         char *detail, size_t detail_size);
void fragment_query_free(fragment_selection *sel);

#endif
