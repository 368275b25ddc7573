/*
 * fuzz_case.c - libFuzzer harness for case_build(): any byte string must
 * give either a model or a list of problems, never a crash, a leak or an
 * allocation beyond the memory limit (ASan enforces -rss_limit_mb and
 * -malloc_limit_mb; the limit below keeps accepted models small so the
 * fuzzer spends its time on the parser, not on meshing).
 */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "case.h"

#define FUZZ_MEMORY_LIMIT ((size_t)64 << 20)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    problems out;
    problems_init(&out);
    case_info info;
    fdem_model *model = case_build((const char *)data, size, FUZZ_MEMORY_LIMIT, &info, &out);
    if (model) {
        /* a built model must be consistent with what case_build reported */
        if (!(info.dt > 0) || info.dt > info.stable_dt || out.count != 0) __builtin_trap();
        fdem_model_destroy(model);
    } else if (out.count + out.dropped == 0 || (out.status != 400 && out.status != 422)) {
        __builtin_trap(); /* a refusal must say why */
    }
    problems_free(&out);
    return 0;
}
