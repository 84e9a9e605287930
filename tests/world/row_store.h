// row_store.h: a growing store of output rows for tests that compare runs
// row by row (an engine_sink / sim_run row callback).
#ifndef CRANESIM_TESTS_ROW_STORE_H
#define CRANESIM_TESTS_ROW_STORE_H

#include "sim.h"

#include <stdlib.h>
#include <string.h>

typedef struct rows {
    int n, cap;
    double* v; // n x SIM_NCOL
} rows;

// The row callback: appends a copy of row (SIM_NCOL values).
static inline int keep_row(void* user, const double* row) {
    rows* r = user;
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 1024;
        r->v = realloc(r->v, (size_t)r->cap * SIM_NCOL * sizeof(double));
    }
    memcpy(r->v + (size_t)r->n++ * SIM_NCOL, row, SIM_NCOL * sizeof(double));
    return 0;
}

#endif
