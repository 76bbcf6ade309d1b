/* Fuzz the Y4M reader the stabiliser tools use (examples/y4m.c): header tags, frame markers,
 * truncation, absurd and odd sizes, unsupported colour spaces. A stream is either refused with a
 * message, or its header gives a supported layout whose frames are read in full or refused, and
 * whose header survives a write/read round trip. */
#define _POSIX_C_SOURCE 200809L
#include "fuzz_util.h"
#include "home.h"
#include "y4m.h"

/* Frames larger than this are not allocated (the fuzzer's inputs are a few KB: they would be
 * truncated anyway, which smaller frames exercise as well). */
#define FZ_MAX_FRAME (4u << 20)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char copy[8192];
    char err[160];
    y4m_info info, again;
    FILE *f;
    size_t bytes;
    uint8_t *buf;
    int k, got;
    if (size == 0 || size > sizeof copy) return 0;
    memcpy(copy, data, size); /* fmemopen wants a writable buffer */
    f = fmemopen(copy, size, "rb");
    if (!f) return 0;
    err[0] = '\0';
    if (y4m_read_header(f, &info, err, sizeof err) != 0) {
        FZ_CHECK(err[0] != '\0');
        fclose(f);
        return 0;
    }
    FZ_CHECK(info.width >= 1 && info.width <= HOME_MAX_SIDE);
    FZ_CHECK(info.height >= 1 && info.height <= HOME_MAX_SIDE);
    FZ_CHECK(info.chroma == 0 || info.chroma == 420 || info.chroma == 422);
    FZ_CHECK(memchr(info.params, 0, sizeof info.params) && memchr(info.colour_tag, 0, sizeof info.colour_tag));
    bytes = y4m_frame_bytes(&info);
    FZ_CHECK(bytes >= (size_t)info.width * (size_t)info.height);
    FZ_CHECK(bytes <= 2u * (size_t)info.width * (size_t)info.height);

    if (bytes <= FZ_MAX_FRAME && (buf = (uint8_t *)malloc(bytes)) != NULL) {
        home_stab_image im;
        /* the mapped reader (home-stab's for files), over the same bytes in a file, agrees with
         * the stream reader on every frame's status and pixels */
        y4m_map map;
        int mapped = 0;
        FILE *file = tmpfile();
        if (file) {
            char map_err[160];
            if (fwrite(data, 1, size, file) == size && fflush(file) == 0 &&
                fseek(file, 0, SEEK_SET) == 0 &&
                y4m_read_header(file, &again, map_err, sizeof map_err) == 0)
                mapped = y4m_map_open(&map, file, ftell(file)) == 0;
            fclose(file);
        }
        for (k = 0; k < 4; k++) {
            err[0] = '\0';
            got = y4m_read_frame(f, &info, buf, err, sizeof err);
            FZ_CHECK(got >= -1 && got <= 1);
            if (mapped) {
                char map_err[160] = "";
                const uint8_t *in_map = NULL;
                FZ_CHECK(y4m_map_frame(&map, &info, &in_map, map_err, sizeof map_err) == got);
                FZ_CHECK(got != 1 || !memcmp(in_map, buf, bytes));
                FZ_CHECK(got != -1 || map_err[0] != '\0');
            }
            if (got <= 0) {
                FZ_CHECK(got == 0 || err[0] != '\0');
                break;
            }
        }
        if (mapped) y4m_map_close(&map);
        /* the planes of the frame view lie inside the frame buffer */
        y4m_image(&info, info.width, buf, &im);
        for (k = 0; k < (info.chroma ? 3 : 1); k++) {
            int rows = k && info.chroma == 420 ? (info.height + 1) / 2 : info.height;
            FZ_CHECK(im.plane[k] >= buf && im.stride[k] > 0);
            FZ_CHECK((size_t)(im.plane[k] - buf) + (size_t)im.stride[k] * (size_t)rows <= bytes);
        }
        free(buf);
    }
    fclose(f);

    /* what the tools write back is read back the same */
    {
        static char out[2048];
        FILE *w = fmemopen(out, sizeof out, "wb");
        if (!w) return 0;
        FZ_CHECK(y4m_write_header(w, &info, info.width) == 0);
        fclose(w);
        w = fmemopen(out, strlen(out), "rb");
        if (!w) return 0;
        FZ_CHECK(y4m_read_header(w, &again, err, sizeof err) == 0);
        FZ_CHECK(again.width == info.width && again.height == info.height && again.chroma == info.chroma);
        fclose(w);
    }
    return 0;
}
