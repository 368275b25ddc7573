/*
 * json_depth.h - how deeply a JSON text nests, read before it is parsed.
 *
 * Why: jansson (2.14, as in Debian 12) parses up to 2048 levels, and a
 * tree that deep costs far more than its text once rewritten: a 1 MB clone
 * patch 2,000 objects deep became 1 GB of indented document (issue 30). A
 * case needs a handful of levels, so every JSON body is held to
 * JSON_MAX_DEPTH before anything is allocated for it.
 *
 * Contract: json_depth_exceeds() scans `size` bytes once (strings and their
 * escapes skipped, so brackets inside strings do not count) and returns 0
 * when no array or object opens deeper than `limit`, else 1 with the line
 * and column (1-based, in bytes) of the first bracket past it. It does not
 * check that the text is valid JSON; the parser does that afterwards.
 *
 * Folder: proto/json/ (its contract: problems.h).
 */
#ifndef FDEM_JSON_DEPTH_H
#define FDEM_JSON_DEPTH_H

#include <stddef.h>

#define JSON_MAX_DEPTH 64 /* levels of arrays and objects in a request body */

int json_depth_exceeds(const char *text, size_t size, int limit, int *line, int *column);

#endif
