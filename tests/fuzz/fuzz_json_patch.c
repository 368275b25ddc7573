/*
 * fuzz_json_patch.c - libFuzzer harness for json_patch_apply() (JSON Patch,
 * RFC 6902, the body of a clone sent as application/json-patch+json): the
 * input is a document, a newline, and a patch. Whatever the bytes, the
 * patch gives either a new document or problems with status 422, each at
 * a pointer into the patch, never a crash or a leak; and the target is
 * never changed, applied or refused (a clone must leave its source as it
 * was, and a failing patch must change nothing).
 */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "json/json_patch.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *text = (const char *)data;
    const char *newline = memchr(text, '\n', size);
    if (!newline)
        return 0;
    size_t doc_size = (size_t)(newline - text);
    json_t *doc = json_loadb(text, doc_size, JSON_DECODE_ANY | JSON_REJECT_DUPLICATES, NULL);
    json_t *patch = json_loadb(newline + 1, size - doc_size - 1,
                               JSON_DECODE_ANY | JSON_REJECT_DUPLICATES, NULL);
    if (doc && patch) {
        json_t *before = json_deep_copy(doc);
        problems p;
        problems_init(&p);
        json_t *out = json_patch_apply(doc, patch, &p);
        if (!json_equal(doc, before)) __builtin_trap(); /* the target is never changed */
        if (out && p.count != 0) __builtin_trap();
        if (!out && (p.count + p.dropped == 0 || p.status != 422)) __builtin_trap();
        for (int i = 0; i < p.count; i++)
            if (p.items[i].pointer[0] != '\0' && p.items[i].pointer[0] != '/') __builtin_trap();
        json_decref(out);
        json_decref(before);
        problems_free(&p);
    }
    json_decref(doc);
    json_decref(patch);
    return 0;
}
