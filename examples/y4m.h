/* YUV4MPEG2 (Y4M) stream reading and writing: 4:2:0 (any siting), 4:2:2 and mono, 8 bit. */
#ifndef HOME_Y4M_H
#define HOME_Y4M_H
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "home_stab.h"

typedef struct y4m_info {
    int width, height;
    int chroma;               /* 420, 422 or 0 (mono) */
    char params[256];         /* the header's other tags (F, I, A, X...) to copy to the output */
    char colour_tag[32];      /* the C tag as read ("C420jpeg"...) or "" */
} y4m_info;

/* Read the stream header. 0 on success; -1 with a reason in err. */
int y4m_read_header(FILE *f, y4m_info *info, char *err, size_t err_size);
/* Bytes of one frame's planes. */
size_t y4m_frame_bytes(const y4m_info *info);
/* Read one frame into buf (y4m_frame_bytes). 1: a frame; 0: clean end of stream; -1: malformed
 * or truncated frame, reason in err. */
int y4m_read_frame(FILE *f, const y4m_info *info, uint8_t *buf, char *err, size_t err_size);
/* Write a header like info's but `width` wide (for side-by-side output). 0 on success. */
int y4m_write_header(FILE *f, const y4m_info *info, int width);
int y4m_write_frame(FILE *f, const uint8_t *buf, size_t bytes);
/* A seekable file's frames read where they lie (POSIX mmap) instead of copied out: a tool that
 * reads a file twice (home-stab's adaptive crop) then copies none of it. The file must not
 * shrink while it is mapped. */
typedef struct y4m_map {
    const uint8_t *base;      /* the whole file, mapped read-only */
    size_t size;
    size_t first, next;       /* offsets of the first frame's header and of the next one */
    size_t released;          /* the pages before this offset are out of memory */
} y4m_map;

/* Map f (its stream header read, its first frame at offset first). 0 on success; -1 when it
 * cannot be mapped (a pipe, an empty file): read it with y4m_read_frame instead. */
int y4m_map_open(y4m_map *m, FILE *f, long first);
/* As y4m_read_frame, with *frame pointing at the frame's planes inside the map. */
int y4m_map_frame(y4m_map *m, const y4m_info *info, const uint8_t **frame, char *err,
                  size_t err_size);
/* Back to the first frame. */
void y4m_map_rewind(y4m_map *m);
/* The frames before `keep` (a frame pointer of this map) will not be read soon: their pages
 * leave the process's memory (they are read from the file again if they are), so a long file
 * does not stay resident. */
void y4m_map_release(y4m_map *m, const uint8_t *keep);
void y4m_map_close(y4m_map *m);
/* View a frame buffer of info's layout (at `width`) as a home_stab_image. */
void y4m_image(const y4m_info *info, int width, uint8_t *buf, home_stab_image *im);
#endif
