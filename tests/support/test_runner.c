/* The runner every test binary shares: one line per test, then "N passed, N failed". */
#include "test.h"
#include <string.h>

int test_failures;

int test_run(const test_case *cases, size_t n, const char *prefix, int argc, char **argv)
{
    int passed = 0, failed = 0;
    size_t i;
    for (i = 0; i < n; i++) {
        int before = test_failures, k, selected = argc < 2;
        for (k = 1; k < argc; k++) selected |= !strcmp(argv[k], cases[i].name);
        if (!selected) continue;
        cases[i].fn();
        if (test_failures == before) { passed++; printf("ok   %s%s\n", prefix, cases[i].name); }
        else { failed++; printf("FAIL %s%s\n", prefix, cases[i].name); }
        fflush(stdout);
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
