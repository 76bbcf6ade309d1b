/* GstHarness tests of the homestab element (examples/gst/gsthomestab.c, compiled in and
 * registered as a static plugin): frames out = frames in, the latency it reports, flushes,
 * renegotiation, refused caps, timestamps, the four formats against each other, statistics
 * messages, settings changed while streaming, frames from a small upstream pool, the warp on
 * several threads. One line per test, then "N passed, N failed".
 * Headless: no plugins but GStreamer's core and this one are loaded. */
#include <gst/gst.h>
#include <gst/check/gstharness.h>
#include <gst/video/video.h>
#include <math.h>
#include <string.h>
#include "test.h"

GST_PLUGIN_STATIC_DECLARE(home);

/* GLib keeps one-time allocations until exit: LeakSanitizer would report them as leaks */
#ifdef __SANITIZE_ADDRESS__
const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "detect_leaks=0"; }
#endif

#define W 192
#define H 144
#define FPS 30
#define FRAME_NS (GST_SECOND / FPS)

/* The test scene: lines and boxes on a gradient (structure HOME registers), seen by a camera
 * shifted by (dx, dy); chroma is a gradient of the same coordinates. */
static double scene(double x, double y)
{
    double v = 70.0 + 0.25 * x + 0.15 * y;
    if (fmod(x + 1000.0, 37.0) < 3.0) v += 90.0;
    if (fmod(y + 1000.0, 29.0) < 2.5) v -= 50.0;
    if (x > 40 && x < 95 && y > 30 && y < 70) v += 60.0;
    if (x > 120 && x < 150 && y > 80 && y < 125) v -= 45.0;
    if (fabs((x - 20.0) - 0.6 * (y - 10.0)) < 2.0) v += 70.0;
    return v < 0 ? 0 : v > 255 ? 255 : v;
}

static void camera(int t, double *dx, double *dy)
{
    *dx = 0.4 * t + 2.5 * sin(1.7 * t) + 1.2 * sin(0.45 * t + 1.0);
    *dy = 2.0 * cos(1.3 * t) + 0.9 * sin(2.9 * t);
}

static uint8_t luma_at(int t, int x, int y)
{
    double dx, dy;
    camera(t, &dx, &dy);
    return (uint8_t)(scene(x + dx, y + dy) + 0.5);
}

static uint8_t chroma_at(int t, int x, int y, int v)
{
    double dx, dy;
    camera(t, &dx, &dy);
    return (uint8_t)(v ? 100.0 + 0.2 * (y + dy) : 90.0 + 0.3 * (x + dx));
}

/* Frame t of the scene (t < 0: frame 0, for a still camera) in format, tightly packed as GStreamer
 * lays these formats out for sizes that are multiples of 8. */
static GstBuffer *make_frame(const char *format, int w, int h, int t)
{
    int tt = t < 0 ? 0 : t, x, y;
    gsize size = !strcmp(format, "GRAY8") ? (gsize)w * h : !strcmp(format, "YUY2") ? (gsize)w * h * 2 : (gsize)w * h * 3 / 2;
    GstBuffer *buf = gst_buffer_new_allocate(NULL, size, NULL);
    GstMapInfo map;
    uint8_t *p;
    gst_buffer_map(buf, &map, GST_MAP_WRITE);
    p = map.data;
    if (!strcmp(format, "YUY2")) {
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x += 2) {
                uint8_t *q = p + (size_t)y * 2 * w + 2 * x;
                q[0] = luma_at(tt, x, y); q[1] = chroma_at(tt, 2 * (x / 2), y, 0);
                q[2] = luma_at(tt, x + 1, y); q[3] = chroma_at(tt, 2 * (x / 2), y, 1);
            }
    } else {
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) p[(size_t)y * w + x] = luma_at(tt, x, y);
        if (!strcmp(format, "I420") || !strcmp(format, "NV12")) {
            uint8_t *c = p + (size_t)w * h;
            int nv12 = !strcmp(format, "NV12");
            for (y = 0; y < h / 2; y++)
                for (x = 0; x < w / 2; x++) {
                    uint8_t u = chroma_at(tt, 2 * x, 2 * y, 0), v = chroma_at(tt, 2 * x, 2 * y, 1);
                    if (nv12) { c[(size_t)y * w + 2 * x] = u; c[(size_t)y * w + 2 * x + 1] = v; }
                    else { c[(size_t)y * (w / 2) + x] = u; c[(size_t)(w / 2) * (h / 2) + (size_t)y * (w / 2) + x] = v; }
                }
        }
    }
    gst_buffer_unmap(buf, &map);
    GST_BUFFER_PTS(buf) = (GstClockTime)tt * FRAME_NS;
    GST_BUFFER_DURATION(buf) = FRAME_NS;
    return buf;
}

static GstHarness *harness(const char *format, int w, int h)
{
    GstHarness *hh = gst_harness_new("homestab");
    gchar *caps = g_strdup_printf("video/x-raw,format=%s,width=%d,height=%d,framerate=%d/1", format, w, h, FPS);
    gst_harness_set_src_caps_str(hh, caps);
    g_free(caps);
    return hh;
}

/* Push frames first .. first + n - 1 (negative: the still frame); the flow of the last push. */
static GstFlowReturn push_frames(GstHarness *hh, const char *format, int w, int h, int first, int n)
{
    GstFlowReturn ret = GST_FLOW_OK;
    int i;
    for (i = 0; i < n && ret == GST_FLOW_OK; i++) {
        GstBuffer *b = make_frame(format, w, h, first < 0 ? -1 : first + i);
        if (first < 0) GST_BUFFER_PTS(b) = (GstClockTime)i * FRAME_NS;
        ret = gst_harness_push(hh, b);
    }
    return ret;
}

static void unref_all(GstBuffer **bufs, int n)
{
    int i;
    for (i = 0; i < n; i++) if (bufs[i]) gst_buffer_unref(bufs[i]);
}

/* Pull up to max buffers; the count. */
static int pull_all(GstHarness *hh, GstBuffer **bufs, int max)
{
    int n = 0;
    GstBuffer *b;
    while ((b = gst_harness_try_pull(hh))) {
        if (n < max) bufs[n++] = b;
        else gst_buffer_unref(b);
    }
    return n;
}

/* Frames out = frames in once EOS drained the held ones; with a lookahead, the held frames
 * come out only then. */
static void frames_out_equal_in(int lookahead)
{
    GstHarness *hh = harness("I420", W, H);
    g_object_set(hh->element, "lookahead", lookahead, NULL);
    CHECK_EQ_INT(push_frames(hh, "I420", W, H, 0, 20), GST_FLOW_OK);
    CHECK_EQ_INT(gst_harness_buffers_received(hh), 20 - lookahead);
    CHECK(gst_harness_push_event(hh, gst_event_new_eos()));
    CHECK_EQ_INT(gst_harness_buffers_received(hh), 20);
    gst_harness_teardown(hh);
}

void test_gst_frames_out_equal_in_causal(void) { frames_out_equal_in(0); }
void test_gst_frames_out_equal_in_lookahead8(void) { frames_out_equal_in(8); }

/* The LATENCY query adds lookahead x frame duration to upstream's. */
void test_gst_latency(void)
{
    GstHarness *hh = harness("NV12", W, H);
    gst_harness_set_upstream_latency(hh, 5 * GST_MSECOND);
    g_object_set(hh->element, "lookahead", 8, NULL);
    CHECK_EQ_INT(push_frames(hh, "NV12", W, H, 0, 2), GST_FLOW_OK);
    CHECK_EQ_INT(gst_harness_query_latency(hh), 5 * GST_MSECOND + 8 * FRAME_NS);
    g_object_set(hh->element, "lookahead", 0, NULL);
    CHECK_EQ_INT(gst_harness_query_latency(hh), 5 * GST_MSECOND);
    gst_harness_teardown(hh);
}

/* FLUSH_START/STOP drops the held frames; the stream restarts (a new path) after it. */
void test_gst_flush_drops_held(void)
{
    GstHarness *hh = harness("I420", W, H);
    GstSegment segment;
    GstBuffer *bufs[32];
    int n, i, ordered = 1;
    g_object_set(hh->element, "lookahead", 6, "post-messages", TRUE, NULL);
    CHECK_EQ_INT(push_frames(hh, "I420", W, H, 0, 10), GST_FLOW_OK);
    CHECK_EQ_INT(gst_harness_buffers_received(hh), 4);
    unref_all(bufs, pull_all(hh, bufs, 32));
    CHECK(gst_harness_push_event(hh, gst_event_new_flush_start()));
    CHECK(gst_harness_push_event(hh, gst_event_new_flush_stop(TRUE)));
    gst_segment_init(&segment, GST_FORMAT_TIME);
    CHECK(gst_harness_push_event(hh, gst_event_new_segment(&segment)));
    CHECK_EQ_INT(push_frames(hh, "I420", W, H, 100, 8), GST_FLOW_OK);
    CHECK_EQ_INT(gst_harness_buffers_received(hh), 4 + 2);
    CHECK(gst_harness_push_event(hh, gst_event_new_eos()));
    n = pull_all(hh, bufs, 32);
    CHECK_EQ_INT(n, 8);   /* the 6 held before the flush never come out */
    for (i = 0; i < n; i++) ordered &= GST_BUFFER_PTS(bufs[i]) == (GstClockTime)(100 + i) * FRAME_NS;
    CHECK(ordered);
    unref_all(bufs, n);
    gst_harness_teardown(hh);
}

/* A caps change to another size drains the old size's frames and continues at the new one. */
void test_gst_renegotiation(void)
{
    GstHarness *hh = harness("I420", W, H);
    GstBuffer *bufs[32];
    int n, i, sizes_ok = 1;
    g_object_set(hh->element, "lookahead", 4, NULL);
    CHECK_EQ_INT(push_frames(hh, "I420", W, H, 0, 6), GST_FLOW_OK);
    gst_harness_set_src_caps_str(hh, "video/x-raw,format=NV12,width=256,height=160,framerate=30/1");
    CHECK_EQ_INT(gst_harness_buffers_received(hh), 6);
    CHECK_EQ_INT(push_frames(hh, "NV12", 256, 160, 6, 7), GST_FLOW_OK);
    CHECK(gst_harness_push_event(hh, gst_event_new_eos()));
    n = pull_all(hh, bufs, 32);
    CHECK_EQ_INT(n, 13);
    for (i = 0; i < n; i++)
        sizes_ok &= gst_buffer_get_size(bufs[i]) == (gsize)(i < 6 ? W * H * 3 / 2 : 256 * 160 * 3 / 2);
    CHECK(sizes_ok);
    unref_all(bufs, n);
    gst_harness_teardown(hh);
}

/* Formats other than I420, NV12, YUY2 and GRAY8, odd sizes and sizes below the library's
 * minimum are refused. */
void test_gst_refuses_caps(void)
{
    static const char *refused[] = {"video/x-raw,format=RGB,width=192,height=144,framerate=30/1",
                                    "video/x-raw,format=I420,width=16,height=16,framerate=30/1"};
    static const char *accepted[] = {"I420", "NV12", "YUY2", "GRAY8"};
    GstHarness *hh = gst_harness_new("homestab");
    GstPad *sink = gst_element_get_static_pad(hh->element, "sink");
    size_t i;
    for (i = 0; i < G_N_ELEMENTS(refused); i++) {
        GstCaps *caps = gst_caps_from_string(refused[i]);
        CHECK(!gst_pad_query_accept_caps(sink, caps));
        gst_caps_unref(caps);
    }
    for (i = 0; i < G_N_ELEMENTS(accepted); i++) {
        gchar *s = g_strdup_printf("video/x-raw,format=%s,width=192,height=144,framerate=30/1", accepted[i]);
        GstCaps *caps = gst_caps_from_string(s);
        CHECK(gst_pad_query_accept_caps(sink, caps));
        gst_caps_unref(caps);
        g_free(s);
    }
    gst_object_unref(sink);
    gst_harness_teardown(hh);

    hh = harness("RGB", W, H);
    CHECK_EQ_INT(gst_harness_push(hh, gst_buffer_new_allocate(NULL, W * H * 3, NULL)), GST_FLOW_NOT_NEGOTIATED);
    gst_harness_teardown(hh);
    /* an odd size passes the caps but not the stabiliser's configuration */
    hh = harness("GRAY8", 191, 143);
    CHECK_EQ_INT(gst_harness_push(hh, gst_buffer_new_allocate(NULL, 192 * 143, NULL)), GST_FLOW_NOT_NEGOTIATED);
    gst_harness_teardown(hh);
}

/* Timestamps, durations and offsets come out as they went in, in order. */
void test_gst_timestamps_preserved(void)
{
    GstHarness *hh = harness("YUY2", W, H);
    GstBuffer *bufs[32];
    int n, i, same = 1;
    g_object_set(hh->element, "lookahead", 3, NULL);
    for (i = 0; i < 12; i++) {
        GstBuffer *b = make_frame("YUY2", W, H, i);
        GST_BUFFER_PTS(b) = 7 * GST_MSECOND + (GstClockTime)i * FRAME_NS;
        GST_BUFFER_DURATION(b) = FRAME_NS - (GstClockTime)i;   /* each its own */
        GST_BUFFER_OFFSET(b) = (guint64)i;
        CHECK_EQ_INT(gst_harness_push(hh, b), GST_FLOW_OK);
    }
    CHECK(gst_harness_push_event(hh, gst_event_new_eos()));
    n = pull_all(hh, bufs, 32);
    CHECK_EQ_INT(n, 12);
    for (i = 0; i < n; i++)
        same &= GST_BUFFER_PTS(bufs[i]) == 7 * GST_MSECOND + (GstClockTime)i * FRAME_NS &&
                GST_BUFFER_DURATION(bufs[i]) == FRAME_NS - (GstClockTime)i && GST_BUFFER_OFFSET(bufs[i]) == (guint64)i;
    CHECK(same);
    unref_all(bufs, n);
    gst_harness_teardown(hh);
}

/* End the stream and take its n outputs into bufs; the harness is gone after. */
static int drain(GstHarness *hh, GstBuffer **bufs, int n)
{
    int got;
    CHECK(gst_harness_push_event(hh, gst_event_new_eos()));
    got = pull_all(hh, bufs, n);
    CHECK_EQ_INT(got, n);
    gst_harness_teardown(hh);
    return got;
}

/* Run n frames of the shaky scene (or the still frame) through homestab; outputs into bufs. */
static int run_clip(const char *format, const char *props_margin, int still, int n, GstBuffer **bufs)
{
    GstHarness *hh = harness(format, W, H);
    g_object_set(hh->element, "lookahead", 4, NULL);
    if (props_margin) g_object_set(hh->element, "margin", (gfloat)g_ascii_strtod(props_margin, NULL), NULL);
    CHECK_EQ_INT(push_frames(hh, format, W, H, still ? -1 : 0, n), GST_FLOW_OK);
    return drain(hh, bufs, n);
}

/* A still camera with no margin: the warp is the identity, every byte of every plane passes. */
void test_gst_still_identity_every_format(void)
{
    static const char *formats[] = {"I420", "NV12", "YUY2", "GRAY8"};
    size_t f;
    for (f = 0; f < G_N_ELEMENTS(formats); f++) {
        GstBuffer *bufs[10], *in = make_frame(formats[f], W, H, -1);
        int n = run_clip(formats[f], "0", 1, 10, bufs), i, same = 1;
        for (i = 0; i < n; i++) {
            GstMapInfo a, b;
            gst_buffer_map(in, &a, GST_MAP_READ);
            gst_buffer_map(bufs[i], &b, GST_MAP_READ);
            same &= a.size == b.size && !memcmp(a.data, b.data, a.size);
            gst_buffer_unmap(bufs[i], &b);
            gst_buffer_unmap(in, &a);
        }
        if (!same) fprintf(stderr, "    %s: output differs from the still input\n", formats[f]);
        CHECK(same);
        unref_all(bufs, n);
        gst_buffer_unref(in);
    }
}

/* The same shaky clip in every format: the warp comes from luma alone, so every format's luma
 * equals I420's, and NV12's interleaved chroma equals I420's planes (YUY2's 4:2:2 chroma is
 * sited differently); and the stabiliser changed the frames. */
void test_gst_formats_agree(void)
{
    enum { N = 16 };
    static const char *formats[] = {"NV12", "YUY2", "GRAY8"};
    GstBuffer *ref[N], *other[N];
    int n = run_clip("I420", NULL, 0, N, ref), i, changed = 0;
    size_t f;
    for (i = 4; i < n; i++) {
        GstBuffer *in = make_frame("I420", W, H, i);
        GstMapInfo a, b;
        gst_buffer_map(in, &a, GST_MAP_READ);
        gst_buffer_map(ref[i], &b, GST_MAP_READ);
        changed += memcmp(a.data, b.data, W * H) != 0;
        gst_buffer_unmap(ref[i], &b);
        gst_buffer_unmap(in, &a);
        gst_buffer_unref(in);
    }
    CHECK_EQ_INT(changed, n - 4);
    for (f = 0; f < G_N_ELEMENTS(formats); f++) {
        int m = run_clip(formats[f], NULL, 0, N, other), luma_same = 1, chroma_same = 1, x, y;
        for (i = 0; i < m && i < n; i++) {
            GstMapInfo a, b;
            gst_buffer_map(ref[i], &a, GST_MAP_READ);
            gst_buffer_map(other[i], &b, GST_MAP_READ);
            for (y = 0; y < H; y++)
                for (x = 0; x < W; x++)
                    luma_same &= a.data[y * W + x] == (!strcmp(formats[f], "YUY2") ? b.data[y * 2 * W + 2 * x] : b.data[y * W + x]);
            if (!strcmp(formats[f], "NV12"))
                for (y = 0; y < H / 2; y++)
                    for (x = 0; x < W / 2; x++)
                        chroma_same &= a.data[W * H + y * (W / 2) + x] == b.data[W * H + y * W + 2 * x] &&
                                       a.data[W * H * 5 / 4 + y * (W / 2) + x] == b.data[W * H + y * W + 2 * x + 1];
            gst_buffer_unmap(other[i], &b);
            gst_buffer_unmap(ref[i], &a);
        }
        if (!luma_same || !chroma_same) fprintf(stderr, "    %s differs from I420 (luma %d, chroma %d)\n", formats[f], luma_same, chroma_same);
        CHECK(m == n && luma_same && chroma_same);
        unref_all(other, m);
    }
    unref_all(ref, n);
}

/* post-messages: one "homestab" element message per output frame, in order, with the frame's
 * timestamp, a known status and the path; the shaky scene registers. */
void test_gst_statistics_messages(void)
{
    GstHarness *hh = harness("I420", W, H);
    GstBus *bus = gst_bus_new();
    GstMessage *m;
    int count = 0, in_order = 1, known = 1, registered = 0, moved = 0;
    gst_element_set_bus(hh->element, bus);
    g_object_set(hh->element, "lookahead", 5, "post-messages", TRUE, NULL);
    CHECK_EQ_INT(push_frames(hh, "I420", W, H, 0, 24), GST_FLOW_OK);
    CHECK(gst_harness_push_event(hh, gst_event_new_eos()));
    while ((m = gst_bus_pop_filtered(bus, GST_MESSAGE_ELEMENT))) {
        const GstStructure *s = gst_message_get_structure(m);
        guint64 frame = G_MAXUINT64, pts = 0;
        const gchar *status = gst_structure_get_string(s, "status");
        double raw_tx = 0, smooth_tx = 0, used = -1;
        if (gst_structure_has_name(s, "homestab")) {
            gst_structure_get_uint64(s, "frame", &frame);
            gst_structure_get_uint64(s, "timestamp", &pts);
            gst_structure_get_double(s, "raw-tx", &raw_tx);
            gst_structure_get_double(s, "smooth-tx", &smooth_tx);
            gst_structure_get_double(s, "correction-used", &used);
            in_order &= frame == (guint64)count && pts == (guint64)count * FRAME_NS;
            known &= status && strstr(" first ok failed implausible cut still restored partial bridged ", status) != NULL &&
                     used >= 0 && used <= 1 && gst_structure_has_field(s, "raw-angle") &&
                     gst_structure_has_field(s, "smooth-log-scale") && gst_structure_has_field(s, "sigma-px");
            registered += status && !strcmp(status, "ok");
            moved += fabs(raw_tx) > 1.0 && fabs(raw_tx - smooth_tx) > 0.05;
            count++;
        }
        gst_message_unref(m);
    }
    CHECK_EQ_INT(count, 24);
    CHECK(in_order);
    CHECK(known);
    CHECK_LT(12, registered);   /* most frames of the scene register */
    CHECK_LT(6, moved);         /* the camera moved, and the smoothed path differs from it */
    gst_element_set_bus(hh->element, NULL);
    gst_object_unref(bus);
    gst_harness_teardown(hh);
}

/* A lookahead set while streaming: the held frames go out, a latency message is posted, the
 * new latency is reported, and no frame is lost. The "cut" action restarts the path at the
 * next frame. */
void test_gst_settings_while_streaming(void)
{
    GstHarness *hh = harness("GRAY8", W, H);
    GstBus *bus = gst_bus_new();
    GstMessage *m;
    int latency_messages = 0, cuts = 0, firsts = 0;
    gst_element_set_bus(hh->element, bus);
    g_object_set(hh->element, "lookahead", 2, "post-messages", TRUE, NULL);
    CHECK_EQ_INT(push_frames(hh, "GRAY8", W, H, 0, 5), GST_FLOW_OK);
    CHECK_EQ_INT(gst_harness_buffers_received(hh), 3);
    g_object_set(hh->element, "lookahead", 6, "margin-x", 0.05f, NULL);
    CHECK_EQ_INT(push_frames(hh, "GRAY8", W, H, 5, 10), GST_FLOW_OK);
    CHECK_EQ_INT(gst_harness_buffers_received(hh), 5 + 10 - 6);
    CHECK_EQ_INT(gst_harness_query_latency(hh), 6 * FRAME_NS);
    g_signal_emit_by_name(hh->element, "cut");
    CHECK_EQ_INT(push_frames(hh, "GRAY8", W, H, 15, 5), GST_FLOW_OK);
    CHECK(gst_harness_push_event(hh, gst_event_new_eos()));
    CHECK_EQ_INT(gst_harness_buffers_received(hh), 20);
    while ((m = gst_bus_pop(bus))) {
        if (GST_MESSAGE_TYPE(m) == GST_MESSAGE_LATENCY) latency_messages++;
        if (GST_MESSAGE_TYPE(m) == GST_MESSAGE_ELEMENT) {
            const gchar *status = gst_structure_get_string(gst_message_get_structure(m), "status");
            cuts += status && !strcmp(status, "cut");
            firsts += status && !strcmp(status, "first");
        }
        gst_message_unref(m);
    }
    CHECK_LT(0, latency_messages);
    CHECK_EQ_INT(cuts, 1);
    CHECK_EQ_INT(firsts, 2);   /* the stream's start and the reconfiguration's */
    gst_element_set_bus(hh->element, NULL);
    gst_object_unref(bus);
    gst_harness_teardown(hh);
}

/* Settings the stabiliser refuses (a downscale of 3): before the caps, the negotiation fails;
 * while streaming, a warning, and the stream goes on with the settings it had. */
void test_gst_invalid_settings_refused(void)
{
    GstHarness *hh = gst_harness_new("homestab");
    GstBus *bus = gst_bus_new();
    GstMessage *m;
    g_object_set(hh->element, "downscale", 3, NULL);
    gst_harness_set_src_caps_str(hh, "video/x-raw,format=I420,width=192,height=144,framerate=30/1");
    CHECK_EQ_INT(push_frames(hh, "I420", W, H, 0, 1), GST_FLOW_NOT_NEGOTIATED);
    gst_harness_teardown(hh);

    hh = harness("I420", W, H);
    gst_element_set_bus(hh->element, bus);
    CHECK_EQ_INT(push_frames(hh, "I420", W, H, 0, 3), GST_FLOW_OK);
    g_object_set(hh->element, "downscale", 3, NULL);
    CHECK_EQ_INT(push_frames(hh, "I420", W, H, 3, 3), GST_FLOW_OK);
    CHECK_EQ_INT(gst_harness_buffers_received(hh), 6);
    m = gst_bus_pop_filtered(bus, GST_MESSAGE_WARNING);
    CHECK(m != NULL);
    if (m) gst_message_unref(m);
    gst_element_set_bus(hh->element, NULL);
    gst_object_unref(bus);
    gst_harness_teardown(hh);
}

/* Frames from an upstream pool of 3 buffers with a lookahead of 8: the element copies what it
 * holds, so the pool never runs dry (a non-blocking acquire fails when it does), and the output
 * is the same as from plain buffers. */
void test_gst_pooled_input_copied(void)
{
    enum { N = 20 };
    GstHarness *hh = harness("NV12", W, H);
    GstBufferPool *pool = gst_video_buffer_pool_new();
    GstStructure *config = gst_buffer_pool_get_config(pool);
    GstCaps *caps = gst_caps_from_string("video/x-raw,format=NV12,width=192,height=144,framerate=30/1");
    GstBuffer *ref[N], *out[N];
    GstBufferPoolAcquireParams dontwait = {GST_FORMAT_UNDEFINED, 0, 0, GST_BUFFER_POOL_ACQUIRE_FLAG_DONTWAIT, {0}};
    int i, n, acquired = 0, same = 1;
    gst_buffer_pool_config_set_params(config, caps, W * H * 3 / 2, 0, 3);
    CHECK(gst_buffer_pool_set_config(pool, config));
    CHECK(gst_buffer_pool_set_active(pool, TRUE));
    g_object_set(hh->element, "lookahead", 8, NULL);
    for (i = 0; i < N; i++) {
        GstBuffer *b = NULL, *frame = make_frame("NV12", W, H, i);
        GstMapInfo map;
        if (gst_buffer_pool_acquire_buffer(pool, &b, &dontwait) != GST_FLOW_OK) { gst_buffer_unref(frame); break; }
        acquired++;
        gst_buffer_map(frame, &map, GST_MAP_READ);
        gst_buffer_fill(b, 0, map.data, map.size);
        gst_buffer_unmap(frame, &map);
        GST_BUFFER_PTS(b) = GST_BUFFER_PTS(frame);
        GST_BUFFER_DURATION(b) = GST_BUFFER_DURATION(frame);
        gst_buffer_unref(frame);
        CHECK_EQ_INT(gst_harness_push(hh, b), GST_FLOW_OK);
    }
    CHECK_EQ_INT(acquired, N);
    CHECK(gst_harness_push_event(hh, gst_event_new_eos()));
    n = pull_all(hh, out, N);
    gst_harness_teardown(hh);
    CHECK_EQ_INT(n, N);
    hh = harness("NV12", W, H);
    g_object_set(hh->element, "lookahead", 8, NULL);
    CHECK_EQ_INT(push_frames(hh, "NV12", W, H, 0, N), GST_FLOW_OK);
    CHECK(gst_harness_push_event(hh, gst_event_new_eos()));
    CHECK_EQ_INT(pull_all(hh, ref, N), N);
    gst_harness_teardown(hh);
    for (i = 0; i < n; i++) {
        GstMapInfo a, b;
        gst_buffer_map(ref[i], &a, GST_MAP_READ);
        gst_buffer_map(out[i], &b, GST_MAP_READ);
        same &= a.size == b.size && !memcmp(a.data, b.data, a.size) && GST_BUFFER_PTS(ref[i]) == GST_BUFFER_PTS(out[i]);
        gst_buffer_unmap(out[i], &b);
        gst_buffer_unmap(ref[i], &a);
    }
    CHECK(same);
    unref_all(out, n);
    unref_all(ref, N);
    gst_buffer_pool_set_active(pool, FALSE);
    gst_object_unref(pool);
    gst_caps_unref(caps);
}

/* The shaky clip through the element with `threads` threads, switched to `later` threads after
 * the first half (the pool restarts at the next warp); n frames out. */
static int run_clip_threads(const char *format, int threads, int later, int n, GstBuffer **bufs)
{
    GstHarness *hh = harness(format, W, H);
    g_object_set(hh->element, "lookahead", 4, "threads", threads, NULL);
    CHECK_EQ_INT(push_frames(hh, format, W, H, 0, n / 2), GST_FLOW_OK);
    g_object_set(hh->element, "threads", later, NULL);
    CHECK_EQ_INT(push_frames(hh, format, W, H, n / 2, n - n / 2), GST_FLOW_OK);
    return drain(hh, bufs, n);
}

/* threads: the warp in bands on a pool gives one thread's bytes, in every format, also when
 * the count changes while streaming (and 0, automatic, is accepted). */
void test_gst_threads_same_bytes(void)
{
    enum { N = 16 };
    static const char *formats[] = {"I420", "NV12", "YUY2", "GRAY8"};
    static const int counts[][2] = {{2, 2}, {3, 3}, {1, 3}, {4, 0}};
    size_t f, c;
    for (f = 0; f < G_N_ELEMENTS(formats); f++) {
        GstBuffer *ref[N], *out[N];
        int n = run_clip_threads(formats[f], 1, 1, N, ref), i;
        for (c = 0; c < G_N_ELEMENTS(counts); c++) {
            int m = run_clip_threads(formats[f], counts[c][0], counts[c][1], N, out), same = m == n;
            for (i = 0; i < m && i < n; i++) {
                GstMapInfo a, b;
                gst_buffer_map(ref[i], &a, GST_MAP_READ);
                gst_buffer_map(out[i], &b, GST_MAP_READ);
                same &= a.size == b.size && !memcmp(a.data, b.data, a.size);
                gst_buffer_unmap(out[i], &b);
                gst_buffer_unmap(ref[i], &a);
            }
            if (!same) fprintf(stderr, "    %s, threads %d then %d: differs from one thread\n", formats[f], counts[c][0], counts[c][1]);
            CHECK(same);
            unref_all(out, m);
        }
        unref_all(ref, n);
    }
}

#define TEST_LIST(X) \
    X(gst_frames_out_equal_in_causal) X(gst_frames_out_equal_in_lookahead8) X(gst_latency) \
    X(gst_flush_drops_held) X(gst_renegotiation) X(gst_refuses_caps) X(gst_timestamps_preserved) \
    X(gst_still_identity_every_format) X(gst_formats_agree) X(gst_statistics_messages) \
    X(gst_settings_while_streaming) X(gst_invalid_settings_refused) X(gst_pooled_input_copied) \
    X(gst_threads_same_bytes)

#define DECLARE(name) void test_##name(void);
TEST_LIST(DECLARE)
#define ENTRY(name) {#name, test_##name},
static const test_case tests[] = {TEST_LIST(ENTRY)};

int main(int argc, char **argv)
{
    /* only GStreamer's core and the element compiled in: no plugin scan, no registry file
     * (the built libgsthome.so, on GST_PLUGIN_PATH, would register homestab a second time) */
    g_unsetenv("GST_PLUGIN_PATH");
    g_unsetenv("GST_PLUGIN_PATH_1_0");
    g_setenv("GST_PLUGIN_SYSTEM_PATH_1_0", "", TRUE);
    g_setenv("GST_REGISTRY_DISABLE", "yes", TRUE);
    gst_init(NULL, NULL);
    g_log_set_always_fatal(G_LOG_LEVEL_CRITICAL | G_LOG_LEVEL_WARNING);
    GST_PLUGIN_STATIC_REGISTER(home);
    return test_run(tests, sizeof tests / sizeof tests[0], "", argc, argv);
}
