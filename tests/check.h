// check.h: a tiny test harness. Each test file is a program; a failed check
// prints file:line and the values, and main() returns the failure count, so
// ctest sees a non-zero exit. Tests never time anything.
#ifndef CRANESIM_CHECK_H
#define CRANESIM_CHECK_H

#include <math.h>
#include <stdio.h>
#include <string.h>

static int check_failures_ = 0;
static int check_count_ = 0;

#define CHECK(cond, ...)                                                                   \
    do {                                                                                   \
        ++check_count_;                                                                    \
        if (!(cond)) {                                                                     \
            ++check_failures_;                                                             \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond);       \
            fprintf(stderr, __VA_ARGS__);                                                  \
            fputc('\n', stderr);                                                           \
        }                                                                                  \
    } while (0)

/// |a - b| <= tol, and both finite.
#define CHECK_NEAR(a, b, tol)                                                              \
    do {                                                                                   \
        double ca_ = (a), cb_ = (b), ct_ = (tol);                                          \
        CHECK(isfinite(ca_) && isfinite(cb_) && fabs(ca_ - cb_) <= ct_,                    \
              "%s = %.10g, %s = %.10g, |diff| = %.3g > tol %.3g", #a, ca_, #b, cb_,        \
              fabs(ca_ - cb_), ct_);                                                       \
    } while (0)

/// |a - b| <= rel * |b|.
#define CHECK_REL(a, b, rel)                                                               \
    do {                                                                                   \
        double ra_ = (a), rb_ = (b), rr_ = (rel);                                          \
        CHECK(isfinite(ra_) && isfinite(rb_) && fabs(ra_ - rb_) <= rr_ * fabs(rb_),        \
              "%s = %.10g, %s = %.10g, rel diff = %.3g > %.3g", #a, ra_, #b, rb_,          \
              fabs(ra_ - rb_) / fabs(rb_), rr_);                                           \
    } while (0)

/// Run one test function by name, or all when no filter is given.
#define RUN_TEST(fn)                                                                       \
    do {                                                                                   \
        if (argc < 2 || strstr(#fn, argv[1])) {                                            \
            int before_ = check_failures_;                                                 \
            fn();                                                                          \
            printf("%-44s %s\n", #fn, check_failures_ == before_ ? "ok" : "FAILED");       \
        }                                                                                  \
    } while (0)

#define TEST_MAIN_END()                                                                    \
    do {                                                                                   \
        printf("%d checks, %d failed\n", check_count_, check_failures_);                   \
        if (check_count_ == 0) {                                                           \
            fprintf(stderr, "no checks ran\n");                                            \
            return 1;                                                                      \
        }                                                                                  \
        return check_failures_ ? 1 : 0;                                                    \
    } while (0)

#endif
