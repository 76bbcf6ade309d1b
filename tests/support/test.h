/* Minimal test framework: TEST(name) functions registered in tests/test_main.c; CHECK records a
 * failure with its location and keeps going. */
#ifndef HOME_TEST_H
#define HOME_TEST_H
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "home.h"

/* The first HOME_ARENA_ALIGN-aligned byte of a static buffer, and the bytes usable from there:
 * C99 aligns a buffer only as much as its widest member type (8 bytes on 32-bit ARM). */
#define ALIGNED_ARENA(buf) ((unsigned char *)(buf) + (-(uintptr_t)(buf) & (HOME_ARENA_ALIGN - 1)))
#define ALIGNED_BYTES(buf) (sizeof(buf) - HOME_ARENA_ALIGN)

extern int test_failures;

typedef struct test_case { const char *name; void (*fn)(void); } test_case;
/* Run the cases named on the command line (all without arguments), print one line each with the
 * prefix, then "N passed, N failed"; returns the exit status. tests/support/test_runner.c. */
int test_run(const test_case *cases, size_t n, const char *prefix, int argc, char **argv);
/* HOME_TEST_SHARD "k/n" (0 <= k < n): this process runs every n-th of the cases, starting at
 * the k-th, so n processes share a binary's cases (tests/run.sh, TEST_JOBS). Sets k = 0, n = 1
 * when it is unset; -1 when it is malformed. */
int test_shard(unsigned *k, unsigned *n);
#define CHECK(cond) do { if (!(cond)) { test_failures++; \
    fprintf(stderr, "    %s:%d: CHECK(%s) failed\n", __FILE__, __LINE__, #cond); } } while (0)
#define CHECK_EQ_INT(a, b) do { long long a_ = (long long)(a), b_ = (long long)(b); if (a_ != b_) { \
    test_failures++; fprintf(stderr, "    %s:%d: %s == %lld, expected %s == %lld\n", \
    __FILE__, __LINE__, #a, a_, #b, b_); } } while (0)
#define CHECK_LT(a, b) do { double a_ = (double)(a), b_ = (double)(b); if (!(a_ < b_)) { \
    test_failures++; fprintf(stderr, "    %s:%d: %s = %g, expected < %s = %g\n", \
    __FILE__, __LINE__, #a, a_, #b, b_); } } while (0)
#endif
