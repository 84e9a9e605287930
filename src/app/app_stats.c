// app_stats.c: sorting and medians of timed repeats (bench, study).
#include "app.h"
#include "engine.h"
#include "world_desc.h"

#include <ctype.h>
#include <limits.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

static int cmp_double(const void* a, const void* b) {
    const double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

void app_sort(double* v, int n) { qsort(v, (size_t)n, sizeof *v, cmp_double); }

double app_median(double* v, int n) {
    app_sort(v, n);
    return v[n / 2];
}
