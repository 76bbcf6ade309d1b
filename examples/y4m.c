#define _DEFAULT_SOURCE /* fileno, mmap, madvise(MADV_DONTNEED) */
#include "y4m.h"
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#define Y4M_MAGIC "YUV4MPEG2"
#define Y4M_MAX_LINE 1024

/* Read one '\n'-terminated line (without it). Returns its length, -1 at EOF before any byte,
 * -2 when it does not fit. */
static int read_line(FILE *f, char *line, size_t size)
{
    size_t n = 0;
    int c;
    while ((c = getc(f)) != EOF && c != '\n') {
        if (n + 1 >= size) return -2;
        line[n++] = (char)c;
    }
    line[n] = 0;
    if (c == EOF) return n ? -2 : -1;
    return (int)n;
}

int y4m_read_header(FILE *f, y4m_info *info, char *err, size_t err_size)
{
    char line[Y4M_MAX_LINE], *tok;
    int n = read_line(f, line, sizeof line);
    memset(info, 0, sizeof *info);
    info->chroma = 420;
    if (n < 0) {
        snprintf(err, err_size, n == -1 ? "empty input (no Y4M header)" : "no Y4M header line");
        return -1;
    }
    if (strncmp(line, Y4M_MAGIC, 9) != 0 || (line[9] != ' ' && line[9] != 0)) {
        snprintf(err, err_size, "not a Y4M stream (header does not start with YUV4MPEG2)");
        return -1;
    }
    for (tok = strtok(line + 9, " "); tok; tok = strtok(NULL, " ")) {
        char *end;
        long v;
        switch (tok[0]) {
        case 'W':
        case 'H':
            v = strtol(tok + 1, &end, 10);
            if (*end || end == tok + 1 || v <= 0 || v > HOME_MAX_SIDE) {
                snprintf(err, err_size, "bad Y4M size tag '%s' (1..%d)", tok, HOME_MAX_SIDE);
                return -1;
            }
            if (tok[0] == 'W') info->width = (int)v; else info->height = (int)v;
            break;
        case 'C':
            /* 8-bit 4:2:0 of any chroma siting; C420p10 and the like are high bit depth */
            if (!strcmp(tok, "C420") || !strcmp(tok, "C420jpeg") || !strcmp(tok, "C420paldv") ||
                !strcmp(tok, "C420mpeg2"))
                info->chroma = 420;
            else if (!strcmp(tok, "C422")) info->chroma = 422;
            else if (!strcmp(tok, "Cmono")) info->chroma = 0;
            else {
                snprintf(err, err_size, "unsupported Y4M colour space '%s' (8-bit C420*, C422, Cmono)", tok);
                return -1;
            }
            snprintf(info->colour_tag, sizeof info->colour_tag, "%s", tok);
            break;
        default:
            if (strlen(info->params) + strlen(tok) + 2 > sizeof info->params) {
                snprintf(err, err_size, "Y4M header too long");
                return -1;
            }
            strcat(info->params, " ");
            strcat(info->params, tok);
        }
    }
    if (!info->width || !info->height) {
        snprintf(err, err_size, "Y4M header lacks W or H");
        return -1;
    }
    if (info->chroma && (info->width % 2 || (info->chroma == 420 && info->height % 2))) {
        snprintf(err, err_size, "odd frame size %dx%d with subsampled chroma", info->width, info->height);
        return -1;
    }
    return 0;
}

static size_t bytes_at(const y4m_info *info, int width)
{
    size_t luma = (size_t)width * info->height;
    return info->chroma == 420 ? luma * 3 / 2 : info->chroma == 422 ? luma * 2 : luma;
}

size_t y4m_frame_bytes(const y4m_info *info) { return bytes_at(info, info->width); }

int y4m_read_frame(FILE *f, const y4m_info *info, uint8_t *buf, char *err, size_t err_size)
{
    char line[Y4M_MAX_LINE];
    size_t need = y4m_frame_bytes(info), got;
    int n = read_line(f, line, sizeof line);
    if (n == -1) return 0;
    if (n < 0 || strncmp(line, "FRAME", 5) != 0 || (line[5] != ' ' && line[5] != 0)) {
        snprintf(err, err_size, "malformed Y4M frame header (expected FRAME)");
        return -1;
    }
    got = fread(buf, 1, need, f);
    if (got != need) {
        snprintf(err, err_size, "truncated Y4M frame (%zu of %zu bytes)", got, need);
        return -1;
    }
    return 1;
}

int y4m_map_open(y4m_map *m, FILE *f, long first)
{
    struct stat st;
    void *base;
    memset(m, 0, sizeof *m);
    if (first < 0 || fstat(fileno(f), &st) || !S_ISREG(st.st_mode) || st.st_size < first ||
        (unsigned long long)st.st_size > (size_t)-1)
        return -1;
    base = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, fileno(f), 0);
    if (base == MAP_FAILED) return -1;
    m->base = base;
    m->size = (size_t)st.st_size;
    m->first = m->next = (size_t)first;
    return 0;
}

/* The FRAME line as read_line() and y4m_read_frame() take it: at most Y4M_MAX_LINE - 1 bytes
 * before its '\n', "FRAME" then a space or the line's end. */
int y4m_map_frame(y4m_map *m, const y4m_info *info, const uint8_t **frame, char *err,
                  size_t err_size)
{
    const size_t need = y4m_frame_bytes(info), left = m->size - m->next;
    const uint8_t *line = m->base + m->next, *end;
    if (!left) return 0;
    end = memchr(line, '\n', left < Y4M_MAX_LINE ? left : Y4M_MAX_LINE);
    if (!end || end - line < 5 || memcmp(line, "FRAME", 5) != 0 ||
        (line[5] != ' ' && line[5] != '\n' && line[5] != 0)) {
        snprintf(err, err_size, "malformed Y4M frame header (expected FRAME)");
        return -1;
    }
    m->next += (size_t)(end - line) + 1;
    if (m->size - m->next < need) {
        snprintf(err, err_size, "truncated Y4M frame (%zu of %zu bytes)", m->size - m->next, need);
        m->next = m->size;
        return -1;
    }
    *frame = m->base + m->next;
    m->next += need;
    return 1;
}

void y4m_map_rewind(y4m_map *m)
{
    m->next = m->first;
    m->released = 0; /* the pages read again may be released again */
}

void y4m_map_release(y4m_map *m, const uint8_t *keep)
{
    const long page = sysconf(_SC_PAGESIZE);
    size_t end;
    if (!m->base || page <= 0 || keep < m->base || keep > m->base + m->size) return;
    end = (size_t)(keep - m->base) / (size_t)page * (size_t)page;
    if (end <= m->released) return;
    /* a read-only private file mapping: the pages come back from the file if read again */
    madvise((void *)(uintptr_t)(m->base + m->released), end - m->released, MADV_DONTNEED);
    m->released = end;
}

void y4m_map_close(y4m_map *m)
{
    if (m->base) munmap((void *)(uintptr_t)m->base, m->size);
    memset(m, 0, sizeof *m);
}

int y4m_write_header(FILE *f, const y4m_info *info, int width)
{
    return fprintf(f, "YUV4MPEG2 W%d H%d%s%s%s\n", width, info->height, info->params,
                   info->colour_tag[0] ? " " : "", info->colour_tag) < 0 ? -1 : 0;
}

int y4m_write_frame(FILE *f, const uint8_t *buf, size_t bytes)
{
    if (fputs("FRAME\n", f) < 0) return -1;
    return fwrite(buf, 1, bytes, f) == bytes ? 0 : -1;
}

void y4m_image(const y4m_info *info, int width, uint8_t *buf, home_stab_image *im)
{
    const size_t luma = (size_t)width * info->height;
    const int ch = info->chroma == 420 ? info->height / 2 : info->height;
    memset(im, 0, sizeof *im);
    im->width = width;
    im->height = info->height;
    im->plane[0] = buf;
    im->stride[0] = width;
    if (!info->chroma) {
        im->format = HOME_STAB_GREY;
        return;
    }
    im->format = info->chroma == 420 ? HOME_STAB_I420 : HOME_STAB_I422;
    im->plane[1] = buf + luma;
    im->plane[2] = buf + luma + (size_t)(width / 2) * ch;
    im->stride[1] = im->stride[2] = width / 2;
}
