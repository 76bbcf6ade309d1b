/* Replays the fuzz corpus (seeds plus every crash ever found, kept as regression inputs) through
 * the harnesses built with the ordinary compiler, so `make test` re-checks them on every build,
 * sanitizer and valgrind run without clang or libFuzzer.
 *   home-fuzz-replay                  every target over tests/fuzz/corpus/<target>/
 *   home-fuzz-replay TARGET FILE...   the given inputs (e.g. a crash file from `make fuzz`)
 * The corpus root can be moved with HOME_FUZZ_CORPUS. A failed invariant aborts (a crash). */
#define _POSIX_C_SOURCE 200809L
#define _FILE_OFFSET_BITS 64 /* 32-bit targets: readdir() of a filesystem with 64-bit inodes */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test.h"

/* Each harness is compiled with LLVMFuzzerTestOneInput renamed (see mk/hardening.mk). */
typedef int (*fuzz_fn)(const uint8_t *data, size_t size);
#define FUZZ_TARGET(name) int fuzz_##name##_one(const uint8_t *data, size_t size);
FUZZ_TARGETS(FUZZ_TARGET)
#undef FUZZ_TARGET
#define FUZZ_TARGET(name) {#name, fuzz_##name##_one},
static const struct { const char *name; fuzz_fn fn; } targets[] = {FUZZ_TARGETS(FUZZ_TARGET)};

static int replay_file(fuzz_fn fn, const char *path)
{
    FILE *f = fopen(path, "rb");
    uint8_t *buf;
    long size;
    if (!f) return -1;
    if (fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return -1;
    }
    /* an exact-size copy, so reads past the input are caught by ASan and valgrind */
    buf = (uint8_t *)malloc(size ? (size_t)size : 1);
    if (!buf || fread(buf, 1, (size_t)size, f) != (size_t)size) {
        free(buf);
        fclose(f);
        return -1;
    }
    fclose(f);
    fn(buf, (size_t)size);
    free(buf);
    return 0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Replays every file of dir in name order; returns how many, or -1 if none could be read. */
static int replay_dir(fuzz_fn fn, const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char **names = NULL, path[4096];
    size_t n = 0, cap = 0, i;
    int done = 0;
    if (!d) return -1;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.') continue;
        if (n == cap) {
            char **nn = (char **)realloc(names, (cap = cap ? 2 * cap : 64) * sizeof *names);
            if (!nn) break;
            names = nn;
        }
        names[n] = (char *)malloc(strlen(e->d_name) + 1);
        if (!names[n]) break;
        strcpy(names[n++], e->d_name);
    }
    closedir(d);
    if (n) qsort(names, n, sizeof *names, cmp_str);
    for (i = 0; i < n; i++) {
        if (snprintf(path, sizeof path, "%s/%s", dir, names[i]) < (int)sizeof path &&
            replay_file(fn, path) == 0)
            done++;
        else fprintf(stderr, "    cannot read %s\n", path);
        free(names[i]);
    }
    free(names);
    return done ? done : -1;
}

int main(int argc, char **argv)
{
    const char *root = getenv("HOME_FUZZ_CORPUS");
    unsigned shard, shards;
    size_t t;
    int passed = 0, failed = 0, k;
    if (!root) root = "tests/fuzz/corpus";
    /* HOME_TEST_SHARD: every n-th target from the k-th (test.h) */
    if (test_shard(&shard, &shards) < 0) {
        fprintf(stderr, "HOME_TEST_SHARD must be k/n with 0 <= k < n\n");
        printf("0 passed, 1 failed\n");
        return 1;
    }
    if (argc >= 3) {
        for (t = 0; t < sizeof targets / sizeof targets[0]; t++) {
            if (strcmp(argv[1], targets[t].name)) continue;
            for (k = 2; k < argc; k++) {
                if (replay_file(targets[t].fn, argv[k]) == 0) { passed++; printf("ok   %s\n", argv[k]); }
                else { failed++; printf("FAIL %s: cannot read\n", argv[k]); }
            }
            printf("%d passed, %d failed\n", passed, failed);
            return failed ? 1 : 0;
        }
        fprintf(stderr, "home-fuzz-replay: unknown target %s\n", argv[1]);
        return 2;
    }
    for (t = 0; t < sizeof targets / sizeof targets[0]; t++) {
        char dir[4096];
        int n;
        if (t % shards != shard) continue;
        n = snprintf(dir, sizeof dir, "%s/%s", root, targets[t].name) < (int)sizeof dir
            ? replay_dir(targets[t].fn, dir) : -1;
        if (n > 0) { passed++; printf("ok   fuzz_replay_%s (%d inputs)\n", targets[t].name, n); }
        else { failed++; printf("FAIL fuzz_replay_%s: no inputs in %s\n", targets[t].name, dir); }
        fflush(stdout);
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
