/* The runner every test binary shares: one line per test, then "N passed, N failed". */
#include "test.h"
#include <stdlib.h>
#include <string.h>

int test_failures;

/* name (its prefix, then the rest) is one of the whitespace-separated words of list */
static int listed(const char *list, const char *prefix, const char *name)
{
    const size_t lp = strlen(prefix), ln = strlen(name);
    const char *p = list;
    while (p && *p) {
        size_t n;
        p += strspn(p, " \t\n");
        n = strcspn(p, " \t\n");
        if (n == lp + ln && !strncmp(p, prefix, lp) && !strncmp(p + lp, name, ln)) return 1;
        p += n;
    }
    return 0;
}

int test_shard(unsigned *k, unsigned *n)
{
    const char *text = getenv("HOME_TEST_SHARD");
    char *end;
    unsigned long a, b;
    *k = 0;
    *n = 1;
    if (!text || !*text) return 0;
    a = strtoul(text, &end, 10);
    if (*end != '/') return -1;
    b = strtoul(end + 1, &end, 10);
    if (*end || b == 0 || a >= b) return -1;
    *k = (unsigned)a;
    *n = (unsigned)b;
    return 0;
}

int test_run(const test_case *cases, size_t n, const char *prefix, int argc, char **argv)
{
    /* HOME_TEST_SKIP: names (as printed) not to run when none is named on the command line;
     * the cross step runs the long accuracy tests natively only (.ci/steps/40-cross.sh) */
    const char *skip = getenv("HOME_TEST_SKIP");
    int passed = 0, failed = 0, skipped = 0;
    unsigned shard = 0, shards = 1, position = 0;
    size_t i;
    if (argc < 2 && test_shard(&shard, &shards) < 0) {
        fprintf(stderr, "HOME_TEST_SHARD must be k/n with 0 <= k < n\n");
        printf("0 passed, 1 failed\n");
        return 1;
    }
    for (i = 0; i < n; i++) {
        int before = test_failures, k, selected = argc < 2;
        for (k = 1; k < argc; k++) selected |= !strcmp(argv[k], cases[i].name);
        if (!selected) continue;
        if (argc < 2 && skip && listed(skip, prefix, cases[i].name)) {
            /* one shard reports the skipped cases */
            if (shard == 0) printf("skip %s%s\n", prefix, cases[i].name);
            skipped += shard == 0;
            continue;
        }
        if (position++ % shards != shard) continue;
        cases[i].fn();
        if (test_failures == before) { passed++; printf("ok   %s%s\n", prefix, cases[i].name); }
        else { failed++; printf("FAIL %s%s\n", prefix, cases[i].name); }
        fflush(stdout);
    }
    if (skipped) printf("%d skipped (HOME_TEST_SKIP)\n", skipped);
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
