/* Binary PGM (P5, maxval 255) reading and writing for libhome's tools and tests. */
#ifndef HOME_PGM_H
#define HOME_PGM_H
#include <stddef.h>
#include <stdint.h>

/* Parse a P5 image held in memory. On success returns 0 and points *pixels into data (rows are
 * width bytes apart). On failure returns -1 and writes a reason to err (if not NULL). Sides
 * must be in [1, max_side]. */
int pgm_parse(const uint8_t *data, size_t size, int max_side, int *width, int *height,
              const uint8_t **pixels, char *err, size_t err_size);

/* Read a whole file into a malloc'ed buffer (caller frees); NULL with err on failure. */
uint8_t *pgm_read_file(const char *path, size_t *size, char *err, size_t err_size);

/* Write a P5 image; returns 0 on success. */
int pgm_write(const char *path, const uint8_t *pixels, int width, int height, ptrdiff_t stride);
#endif
