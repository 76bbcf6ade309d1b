/* Helpers shared by libhome's fuzz harnesses: a byte reader that turns the fuzzer's input into
 * typed values (running out of bytes yields zeros, so every input is usable), and a check that
 * aborts on a broken invariant so libFuzzer (or the replay driver) reports it as a crash. */
#ifndef HOME_FUZZ_UTIL_H
#define HOME_FUZZ_UTIL_H
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct fz_reader {
    const uint8_t *data;
    size_t size, pos;
} fz_reader;

static inline uint32_t fz_u8(fz_reader *r)
{
    return r->pos < r->size ? r->data[r->pos++] : 0u;
}

static inline uint32_t fz_u16(fz_reader *r)
{
    uint32_t lo = fz_u8(r);
    return lo | fz_u8(r) << 8;
}

static inline uint32_t fz_u32(fz_reader *r)
{
    uint32_t lo = fz_u16(r);
    return lo | fz_u16(r) << 16;
}

/* An integer in [lo, hi] (hi - lo < 65536). */
static inline int fz_range(fz_reader *r, int lo, int hi)
{
    return lo + (int)(fz_u16(r) % (uint32_t)(hi - lo + 1));
}

/* Any float bit pattern, NaN and Inf included. */
static inline float fz_float_bits(fz_reader *r)
{
    uint32_t bits = fz_u32(r);
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

static inline size_t fz_remaining(const fz_reader *r)
{
    return r->size - r->pos;
}

/* The first 16-byte aligned byte of a buffer (C99 statics are only as aligned as their widest
 * member type: 8 bytes on 32-bit ARM); callers keep 16 bytes of slack. */
static inline unsigned char *fz_align16(unsigned char *p)
{
    return p + (-(uintptr_t)p & 15u);
}

/* The harnesses' own pixel loops (making test images) are not worth coverage: traced compares
 * there were a fifth of an execution. */
#if defined(__clang__)
#define FZ_NO_COVERAGE __attribute__((no_sanitize("coverage")))
#else
#define FZ_NO_COVERAGE
#endif

#define FZ_CHECK(cond) do { if (!(cond)) { \
    fprintf(stderr, "%s:%d: invariant failed: %s\n", __FILE__, __LINE__, #cond); abort(); } } while (0)
#endif
