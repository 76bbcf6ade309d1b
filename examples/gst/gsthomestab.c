/* homestab: a GStreamer video stabiliser on libhome's home_stab (plugin "home").
 *
 *   gst-launch-1.0 libcamerasrc ! video/x-raw,format=NV12,width=1280,height=720 \
 *     ! homestab lookahead=8 ! videoconvert ! autovideosink
 *
 * A GstVideoFilter on I420, NV12, YUY2 and GRAY8, the same size in and out. Each input frame's
 * luma is pushed to the stabiliser as it arrives; the frame itself is held until the stabiliser
 * reports its warp, `lookahead` frames later, and then goes through the base class's transform
 * path (home_stab_warp into a fresh output buffer, timestamps and duration kept). That hold is
 * real latency: the LATENCY query adds lookahead x frame duration. EOS, a caps change, a new
 * segment or stream drain the held frames through home_stab_flush; FLUSH_STOP drops them and
 * resets the path. Properties are home-stab's options; a change while streaming drains the held
 * frames and reconfigures at the next frame. With post-messages, every output frame posts an
 * element message "homestab" with its raw and smoothed camera path (docs/gstreamer.md).
 *
 * Memory: the stabiliser's arena is allocated once per configuration (the library itself never
 * allocates). Held frames that come from an upstream buffer pool (a camera's few buffers) are
 * copied into the element's own pool (lookahead + 1 buffers at most, allocated as first needed),
 * so upstream gets its buffers back at once; other input buffers are held by reference.
 *
 * Threads: with threads = N > 1 the warp runs in N row bands (home_stab_warp_rows) on a fixed
 * pool of N - 1 workers and the streaming thread (examples/eis_pool.h), started at the first
 * warp and kept; the bytes are one thread's. Registration does not overlap the warp here, as it
 * does in eis-v4l2: the base class renders each frame in the call that pushed its successor,
 * and overlapping them would hold every frame one more frame. */
#include <gst/gst.h>
#include <gst/video/video.h>
#include <gst/video/gstvideofilter.h>
#include <string.h>
#include "home_stab.h"
#include "eis_pool.h"

/* GST_PLUGIN_DEFINE names the package */
#define PACKAGE "libhome"
#define GST_HOME_STAB_VERSION HOME_VERSION_STRING

GST_DEBUG_CATEGORY_STATIC(home_stab_debug);
#define GST_CAT_DEFAULT home_stab_debug

#define GST_TYPE_HOME_STAB (gst_home_stab_get_type())
G_DECLARE_FINAL_TYPE(GstHomeStab, gst_home_stab, GST, HOME_STAB, GstVideoFilter)

/* A frame waiting for its warp. */
typedef struct held_frame {
    GstBuffer *buffer;        /* the input buffer (a reference) or the element's copy of it */
    long index;               /* push order since the stabiliser was configured or reset */
    home_result reg;          /* its registration to the previous frame */
    double ms_register;
} held_frame;

/* Lookahead frames held, plus the newest one pushed. */
#define HELD_CAPACITY (HOME_STAB_MAX_LOOKAHEAD + 1)

struct _GstHomeStab {
    GstVideoFilter parent;

    /* properties (object lock) */
    gint lookahead;
    gfloat margin, margin_x, margin_y; /* margin_x, margin_y < 0: `margin` */
    gfloat smoothing, ease;
    gint downscale, keypoints, refine_finest, hough_downscale, theta_bins;
    gboolean refine, post_messages;
    gint threads;                 /* 0: eis_pool_auto_threads() */
    gboolean settings_changed;    /* since the stabiliser was configured */
    gboolean cut_requested;       /* the "cut" action signal, for the next frame */

    /* streaming thread */
    home_stab_config cfg;
    home_stab *stab;              /* NULL until the caps are set */
    gpointer arena_block;         /* g_malloc'd; the arena starts at its first aligned byte */
    gsize arena_block_bytes;
    held_frame held[HELD_CAPACITY];
    gint held_first, held_count;
    long pushed;
    home_stab_output due;         /* the warp reported by the last push, until rendered */
    gboolean have_due;
    const home_stab_output *rendering; /* the output transform_frame applies */
    GstBufferPool *copy_pool;     /* for held frames from upstream pools; NULL without lookahead */
    GstClockTime last_duration;   /* of the last input buffer: the latency without a framerate */
    eis_pool *pool;               /* the warp's threads; NULL until the first warp */
};

G_DEFINE_TYPE(GstHomeStab, gst_home_stab, GST_TYPE_VIDEO_FILTER)

enum {
    PROP_0,
    PROP_LOOKAHEAD,
    PROP_MARGIN,
    PROP_MARGIN_X,
    PROP_MARGIN_Y,
    PROP_SMOOTHING,
    PROP_EASE,
    PROP_DOWNSCALE,
    PROP_KEYPOINTS,
    PROP_REFINE,
    PROP_REFINE_FINEST,
    PROP_HOUGH_DOWNSCALE,
    PROP_THETA_BINS,
    PROP_POST_MESSAGES,
    PROP_THREADS
};

enum { SIGNAL_CUT, N_SIGNALS };
static guint home_stab_signals[N_SIGNALS];

/* the library's frame sizes (home_limits.h); even sizes only, which caps cannot say: set_info
 * refuses odd ones */
#define HOME_STAB_CAPS                                                                        \
    "video/x-raw, format = (string) { I420, NV12, YUY2, GRAY8 }, "                            \
    "width = (int) [ " G_STRINGIFY(HOME_MIN_SIDE) ", " G_STRINGIFY(HOME_MAX_SIDE) " ], "      \
    "height = (int) [ " G_STRINGIFY(HOME_MIN_SIDE) ", " G_STRINGIFY(HOME_MAX_SIDE) " ], "     \
    "framerate = " GST_VIDEO_FPS_RANGE

static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(HOME_STAB_CAPS));
static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(HOME_STAB_CAPS));

static const char *motion_status_name(int status)
{
    static const char *names[] = {"first", "ok",    "failed",  "implausible",
                                  "cut",   "still", "restored", "partial", "bridged"};
    return status >= 0 && status < (int)G_N_ELEMENTS(names) ? names[status] : "unknown";
}

static int home_format(GstVideoFormat format)
{
    switch (format) {
    case GST_VIDEO_FORMAT_I420: return HOME_STAB_I420;
    case GST_VIDEO_FORMAT_NV12: return HOME_STAB_NV12;
    case GST_VIDEO_FORMAT_YUY2: return HOME_STAB_YUYV;
    case GST_VIDEO_FORMAT_GRAY8: return HOME_STAB_GREY;
    default: return 0;
    }
}

/* A mapped frame as the library sees it (planes and strides as mapped, so padded rows and
 * upstream's video meta are honoured). */
static void frame_image(GstVideoFrame *frame, home_stab_image *im)
{
    guint k;
    memset(im, 0, sizeof *im);
    im->format = home_format(GST_VIDEO_FRAME_FORMAT(frame));
    im->width = GST_VIDEO_FRAME_WIDTH(frame);
    im->height = GST_VIDEO_FRAME_HEIGHT(frame);
    for (k = 0; k < GST_VIDEO_FRAME_N_PLANES(frame) && k < 3; k++) {
        im->plane[k] = GST_VIDEO_FRAME_PLANE_DATA(frame, k);
        im->stride[k] = GST_VIDEO_FRAME_PLANE_STRIDE(frame, k);
    }
}

static double monotonic_ms(void *user)
{
    (void)user;
    return (double)g_get_monotonic_time() / 1e3;
}

/* The stabiliser's configuration for a width x height stream from the properties; clears
 * settings_changed. HOME_OK or the library's status. */
static int settings_config(GstHomeStab *self, int width, int height, home_stab_config *cfg)
{
    int status = home_stab_default_config(cfg, width, height);
    GST_OBJECT_LOCK(self);
    cfg->margin_x = self->margin_x >= 0 ? self->margin_x : self->margin;
    cfg->margin_y = self->margin_y >= 0 ? self->margin_y : self->margin;
    cfg->smoothing = self->smoothing;
    cfg->lookahead = self->lookahead;
    cfg->ease = self->ease;
    if (self->downscale > 0) cfg->downscale = self->downscale;
    cfg->keypoints_per_sign = self->keypoints;
    cfg->refine = self->refine ? 1 : 0;
    cfg->refine_finest_level = self->refine_finest;
    if (self->hough_downscale > 0) cfg->hough_downscale = self->hough_downscale;
    cfg->theta_bins = self->theta_bins;
    self->settings_changed = FALSE;
    GST_OBJECT_UNLOCK(self);
    cfg->clock = monotonic_ms;
    cfg->clock_user = NULL;
    return status == HOME_OK ? home_stab_validate_config(cfg) : status;
}

static held_frame *held_at(GstHomeStab *self, gint i)
{
    return &self->held[(self->held_first + i) % HELD_CAPACITY];
}

static void drop_held(GstHomeStab *self)
{
    while (self->held_count > 0) {
        held_frame *h = held_at(self, 0);
        gst_buffer_replace(&h->buffer, NULL);
        self->held_first = (self->held_first + 1) % HELD_CAPACITY;
        self->held_count--;
    }
    self->held_first = 0;
    self->have_due = FALSE;
}

static void release_copy_pool(GstHomeStab *self)
{
    if (!self->copy_pool) return;
    gst_buffer_pool_set_active(self->copy_pool, FALSE);
    gst_object_unref(self->copy_pool);
    self->copy_pool = NULL;
}

/* Everything of the current configuration: held frames, the pools, the arena. */
static void release_all(GstHomeStab *self)
{
    drop_held(self);
    release_copy_pool(self);
    eis_pool_stop(self->pool);
    self->pool = NULL;
    self->stab = NULL;
    g_free(self->arena_block);
    self->arena_block = NULL;
    self->arena_block_bytes = 0;
    self->pushed = 0;
}

/* The pool held frames are copied into: buffers of the negotiated layout (no video meta, so
 * the copies map by the caps' default strides), allocated as first needed (never when upstream
 * has no pool) and kept: lookahead + 1 at most are out at a time. */
static gboolean make_copy_pool(GstHomeStab *self, GstCaps *caps, const GstVideoInfo *info)
{
    GstStructure *config;
    release_copy_pool(self);
    if (self->cfg.lookahead == 0) return TRUE;
    self->copy_pool = gst_video_buffer_pool_new();
    config = gst_buffer_pool_get_config(self->copy_pool);
    gst_buffer_pool_config_set_params(config, caps, (guint)GST_VIDEO_INFO_SIZE(info), 0, 0);
    if (!gst_buffer_pool_set_config(self->copy_pool, config) ||
        !gst_buffer_pool_set_active(self->copy_pool, TRUE)) {
        release_copy_pool(self);
        return FALSE;
    }
    return TRUE;
}

/* Lay the stabiliser out for cfg, growing the arena only when it needs more. */
static int init_stabiliser(GstHomeStab *self, const home_stab_config *cfg)
{
    size_t need = home_stab_arena_size(cfg);
    gpointer arena;
    int status;
    if (need == 0) return HOME_E_CONFIG;
    if (self->arena_block_bytes < need + HOME_ARENA_ALIGN) {
        self->stab = NULL;
        g_free(self->arena_block);
        self->arena_block_bytes = need + HOME_ARENA_ALIGN;
        self->arena_block = g_malloc(self->arena_block_bytes);
    }
    arena = (guint8 *)self->arena_block + (-(guintptr)self->arena_block & (HOME_ARENA_ALIGN - 1));
    status = home_stab_init(&self->stab, cfg, arena, self->arena_block_bytes - HOME_ARENA_ALIGN, NULL);
    if (status != HOME_OK) {
        self->stab = NULL;
        return status;
    }
    self->cfg = *cfg;
    self->pushed = 0;
    GST_INFO_OBJECT(self, "%dx%d, lookahead %d, margins %.3f x %.3f, arena %" G_GSIZE_FORMAT " bytes",
                    cfg->width, cfg->height, cfg->lookahead, cfg->margin_x, cfg->margin_y, (gsize)need);
    return HOME_OK;
}

static void post_statistics(GstHomeStab *self, const home_stab_output *o, const held_frame *h,
                            GstBuffer *outbuf)
{
    GstBaseTransform *trans = GST_BASE_TRANSFORM(self);
    GstClockTime pts = GST_BUFFER_PTS(outbuf);
    GstStructure *s = gst_structure_new(
        "homestab",
        "frame", G_TYPE_UINT64, (guint64)o->frame,
        "timestamp", G_TYPE_UINT64, (guint64)pts,
        "stream-time", G_TYPE_UINT64,
        (guint64)gst_segment_to_stream_time(&trans->segment, GST_FORMAT_TIME, pts),
        "running-time", G_TYPE_UINT64,
        (guint64)gst_segment_to_running_time(&trans->segment, GST_FORMAT_TIME, pts),
        "duration", G_TYPE_UINT64, (guint64)GST_BUFFER_DURATION(outbuf),
        "status", G_TYPE_STRING, motion_status_name(o->motion_status),
        "raw-tx", G_TYPE_DOUBLE, o->raw.tx, "raw-ty", G_TYPE_DOUBLE, o->raw.ty,
        "raw-angle", G_TYPE_DOUBLE, o->raw.angle, "raw-log-scale", G_TYPE_DOUBLE, o->raw.log_scale,
        "smooth-tx", G_TYPE_DOUBLE, o->smooth.tx, "smooth-ty", G_TYPE_DOUBLE, o->smooth.ty,
        "smooth-angle", G_TYPE_DOUBLE, o->smooth.angle,
        "smooth-log-scale", G_TYPE_DOUBLE, o->smooth.log_scale,
        "correction-used", G_TYPE_DOUBLE, o->correction_used,
        "model", G_TYPE_STRING, o->frame > 0 && h->reg.ok ? home_model_name(h->reg.model) : "none",
        "sigma-px", G_TYPE_DOUBLE, o->frame > 0 ? (double)h->reg.sigma_px : 0.0,
        "inliers", G_TYPE_INT, h->reg.inliers,
        "register-ms", G_TYPE_DOUBLE, h->ms_register,
        NULL);
    gst_element_post_message(GST_ELEMENT(self), gst_message_new_element(GST_OBJECT(self), s));
}

/* Send the oldest held frame through the base class's transform path with o's warp. */
static GstFlowReturn render(GstHomeStab *self, const home_stab_output *o, GstBuffer **outbuf)
{
    GstBaseTransform *trans = GST_BASE_TRANSFORM(self);
    held_frame h;
    GstFlowReturn ret;
    gboolean post;
    /* frames are reported in push order: anything older than o's frame was dropped */
    while (self->held_count > 0 && held_at(self, 0)->index < o->frame) {
        gst_buffer_replace(&held_at(self, 0)->buffer, NULL);
        self->held_first = (self->held_first + 1) % HELD_CAPACITY;
        self->held_count--;
    }
    if (self->held_count == 0 || held_at(self, 0)->index != o->frame) {
        GST_ELEMENT_ERROR(self, STREAM, FAILED, (NULL), ("frame %ld due but not held", o->frame));
        return GST_FLOW_ERROR;
    }
    h = *held_at(self, 0);
    held_at(self, 0)->buffer = NULL;
    self->held_first = (self->held_first + 1) % HELD_CAPACITY;
    self->held_count--;

    trans->queued_buf = h.buffer;   /* the parent's generate_output takes it */
    self->rendering = o;
    ret = GST_BASE_TRANSFORM_CLASS(gst_home_stab_parent_class)->generate_output(trans, outbuf);
    self->rendering = NULL;
    GST_OBJECT_LOCK(self);
    post = self->post_messages;
    GST_OBJECT_UNLOCK(self);
    if (ret == GST_FLOW_OK && *outbuf && post) post_statistics(self, o, &h, *outbuf);
    return ret;
}

/* Every held frame out, through home_stab_flush (the path's end eased as at a stream's end);
 * the next push continues the stream. */
static GstFlowReturn drain(GstHomeStab *self)
{
    GstBaseTransform *trans = GST_BASE_TRANSFORM(self);
    GstFlowReturn ret = GST_FLOW_OK;
    home_stab_output o;
    if (!self->stab) return GST_FLOW_OK;
    GST_DEBUG_OBJECT(self, "draining %d held frames", self->held_count);
    for (;;) {
        GstBuffer *outbuf = NULL;
        if (self->have_due) {
            o = self->due;
            self->have_due = FALSE;
        } else if (home_stab_flush(self->stab, &o) != HOME_OK || !o.ready) {
            break;
        }
        ret = render(self, &o, &outbuf);
        if (ret == GST_FLOW_OK && outbuf) ret = gst_pad_push(GST_BASE_TRANSFORM_SRC_PAD(trans), outbuf);
        if (ret != GST_FLOW_OK) break;
    }
    drop_held(self);
    return ret;
}

static void post_latency_change(GstHomeStab *self)
{
    gst_element_post_message(GST_ELEMENT(self), gst_message_new_latency(GST_OBJECT(self)));
}

/* Caps are set (first or changed; held frames of the old caps were drained in sink_event). */
static gboolean gst_home_stab_set_info(GstVideoFilter *filter, GstCaps *incaps, GstVideoInfo *in_info,
                                       GstCaps *outcaps, GstVideoInfo *out_info)
{
    GstHomeStab *self = GST_HOME_STAB(filter);
    home_stab_config cfg;
    int old_lookahead = self->stab ? self->cfg.lookahead : 0, status;
    (void)outcaps;
    if (GST_VIDEO_INFO_FORMAT(in_info) != GST_VIDEO_INFO_FORMAT(out_info) ||
        GST_VIDEO_INFO_WIDTH(in_info) != GST_VIDEO_INFO_WIDTH(out_info) ||
        GST_VIDEO_INFO_HEIGHT(in_info) != GST_VIDEO_INFO_HEIGHT(out_info))
        return FALSE;
    status = settings_config(self, GST_VIDEO_INFO_WIDTH(in_info), GST_VIDEO_INFO_HEIGHT(in_info), &cfg);
    if (status == HOME_OK) {
        drop_held(self);
        status = init_stabiliser(self, &cfg);
    }
    if (status != HOME_OK) {
        GST_ELEMENT_ERROR(self, CORE, NEGOTIATION, (NULL),
                          ("cannot stabilise %dx%d %s with these settings: %s",
                           GST_VIDEO_INFO_WIDTH(in_info), GST_VIDEO_INFO_HEIGHT(in_info),
                           GST_VIDEO_INFO_NAME(in_info), home_strerror(status)));
        return FALSE;
    }
    if (!make_copy_pool(self, incaps, in_info)) {
        GST_ELEMENT_ERROR(self, RESOURCE, NO_SPACE_LEFT, (NULL), ("cannot set up the pool for held frames"));
        return FALSE;
    }
    if (cfg.lookahead != old_lookahead) post_latency_change(self);
    return TRUE;
}

/* A property changed while streaming: the held frames go out under the old settings, then the
 * stabiliser starts over with the new ones (an invalid combination keeps the old ones). */
static GstFlowReturn apply_changed_settings(GstHomeStab *self)
{
    GstVideoFilter *filter = GST_VIDEO_FILTER(self);
    home_stab_config cfg;
    int old_lookahead = self->cfg.lookahead, status;
    GstFlowReturn ret;
    GstCaps *caps;
    status = settings_config(self, self->cfg.width, self->cfg.height, &cfg);
    if (status != HOME_OK) {
        GST_ELEMENT_WARNING(self, LIBRARY, SETTINGS, (NULL),
                            ("settings rejected, keeping the previous ones: %s", home_strerror(status)));
        return GST_FLOW_OK;
    }
    if ((ret = drain(self)) != GST_FLOW_OK) return ret;
    status = init_stabiliser(self, &cfg);
    caps = gst_pad_get_current_caps(GST_BASE_TRANSFORM_SINK_PAD(self));
    if (status != HOME_OK || !caps || !make_copy_pool(self, caps, &filter->in_info)) {
        if (caps) gst_caps_unref(caps);
        GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS, (NULL), ("cannot reconfigure: %s", home_strerror(status)));
        return GST_FLOW_ERROR;
    }
    gst_caps_unref(caps);
    if (cfg.lookahead != old_lookahead) post_latency_change(self);
    return GST_FLOW_OK;
}

/* The frame to hold: the input itself, or a copy when it belongs to an upstream pool (the
 * input is released then; in_frame, its mapping, keeps its own reference). NULL when no copy
 * could be made, the input released too. */
static GstBuffer *frame_to_hold(GstHomeStab *self, GstBuffer *input, GstVideoFrame *in_frame)
{
    GstVideoFrame copy_frame;
    GstBuffer *copy = NULL;
    if (!input->pool || !self->copy_pool) return input;
    if (gst_buffer_pool_acquire_buffer(self->copy_pool, &copy, NULL) == GST_FLOW_OK &&
        gst_video_frame_map(&copy_frame, &GST_VIDEO_FILTER(self)->in_info, copy, GST_MAP_WRITE)) {
        gst_video_frame_copy(&copy_frame, in_frame);
        gst_video_frame_unmap(&copy_frame);
        gst_buffer_copy_into(copy, input, GST_BUFFER_COPY_FLAGS | GST_BUFFER_COPY_TIMESTAMPS, 0, -1);
    } else if (copy) {
        gst_buffer_unref(copy);
        copy = NULL;
    }
    gst_buffer_unref(input);
    return copy;
}

/* Every input: its luma to the stabiliser now, the frame held until its warp is due. */
static GstFlowReturn gst_home_stab_submit_input_buffer(GstBaseTransform *trans, gboolean is_discont,
                                                       GstBuffer *input)
{
    GstHomeStab *self = GST_HOME_STAB(trans);
    GstVideoFrame frame;
    home_stab_image image;
    home_stab_output o;
    GstBuffer *buf;
    gboolean changed, cut;
    held_frame *h;
    int status;
    GstFlowReturn ret =
        GST_BASE_TRANSFORM_CLASS(gst_home_stab_parent_class)->submit_input_buffer(trans, is_discont, input);
    if (ret != GST_FLOW_OK || !trans->queued_buf) return ret;
    buf = trans->queued_buf;
    trans->queued_buf = NULL;
    if (!self->stab) {
        gst_buffer_unref(buf);
        return GST_FLOW_NOT_NEGOTIATED;
    }
    GST_OBJECT_LOCK(self);
    changed = self->settings_changed;
    cut = self->cut_requested;
    self->cut_requested = FALSE;
    GST_OBJECT_UNLOCK(self);
    if (changed && (ret = apply_changed_settings(self)) != GST_FLOW_OK) {
        gst_buffer_unref(buf);
        return ret;
    }
    if (cut) home_stab_cut(self->stab);
    if (GST_BUFFER_DURATION_IS_VALID(buf)) self->last_duration = GST_BUFFER_DURATION(buf);

    if (!gst_video_frame_map(&frame, &GST_VIDEO_FILTER(self)->in_info, buf, GST_MAP_READ)) {
        gst_buffer_unref(buf);
        GST_ELEMENT_ERROR(self, STREAM, FAILED, (NULL), ("cannot map the input frame"));
        return GST_FLOW_ERROR;
    }
    frame_image(&frame, &image);
    status = home_stab_push(self->stab, &image, &o);
    if (status == HOME_OK && self->cfg.lookahead > 0) buf = frame_to_hold(self, buf, &frame);
    gst_video_frame_unmap(&frame);
    if (status != HOME_OK || !buf) {
        if (buf) gst_buffer_unref(buf);
        GST_ELEMENT_ERROR(self, STREAM, FAILED, (NULL),
                          ("%s", status != HOME_OK ? home_strerror(status) : "cannot copy the frame to hold"));
        return GST_FLOW_ERROR;
    }
    h = held_at(self, self->held_count);
    h->buffer = buf;
    h->index = self->pushed++;
    h->reg = o.reg;
    h->ms_register = o.ms_register;
    self->held_count++;
    if (o.ready) {
        self->due = o;
        self->have_due = TRUE;
    }
    return GST_FLOW_OK;
}

/* Nothing until a warp is due; then the oldest held frame, warped. */
static GstFlowReturn gst_home_stab_generate_output(GstBaseTransform *trans, GstBuffer **outbuf)
{
    GstHomeStab *self = GST_HOME_STAB(trans);
    *outbuf = NULL;
    if (!self->have_due) return GST_FLOW_OK;
    self->have_due = FALSE;
    return render(self, &self->due, outbuf);
}

static GstFlowReturn gst_home_stab_transform_frame(GstVideoFilter *filter, GstVideoFrame *in_frame,
                                                   GstVideoFrame *out_frame)
{
    GstHomeStab *self = GST_HOME_STAB(filter);
    home_stab_image src, dst;
    int status, threads;
    if (!self->rendering) {   /* only render() sends frames this way */
        GST_ELEMENT_ERROR(self, STREAM, FAILED, (NULL), ("a frame reached the transform without a warp"));
        return GST_FLOW_ERROR;
    }
    GST_OBJECT_LOCK(self);
    threads = self->threads ? self->threads : eis_pool_auto_threads();
    GST_OBJECT_UNLOCK(self);
    if (self->pool && eis_pool_threads(self->pool) != threads) {
        eis_pool_stop(self->pool);
        self->pool = NULL;
    }
    if (!self->pool && threads > 1 && eis_pool_start(&self->pool, threads))
        GST_WARNING_OBJECT(self, "cannot start %d threads: warping on one", threads);
    frame_image(in_frame, &src);
    frame_image(out_frame, &dst);
    status = self->pool ? eis_pool_warp(self->pool, self->rendering->warp, &src, &dst)
                        : home_stab_warp(self->rendering->warp, &src, &dst);
    if (status != HOME_OK) {
        GST_ELEMENT_ERROR(self, STREAM, FAILED, (NULL), ("warp: %s", home_strerror(status)));
        return GST_FLOW_ERROR;
    }
    return GST_FLOW_OK;
}

static gboolean gst_home_stab_sink_event(GstBaseTransform *trans, GstEvent *event)
{
    GstHomeStab *self = GST_HOME_STAB(trans);
    switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_FLUSH_STOP:
        drop_held(self);
        if (self->stab) home_stab_reset(self->stab);
        self->pushed = 0;
        break;
    case GST_EVENT_EOS:
    case GST_EVENT_SEGMENT:
        drain(self);
        break;
    case GST_EVENT_STREAM_START:
        /* another stream: what is held ends the old one, and the path restarts */
        drain(self);
        if (self->stab && self->pushed > 0) home_stab_cut(self->stab);
        break;
    case GST_EVENT_CAPS: {
        GstCaps *caps, *current = gst_pad_get_current_caps(GST_BASE_TRANSFORM_SINK_PAD(trans));
        gst_event_parse_caps(event, &caps);
        if (current && !gst_caps_is_equal(caps, current)) drain(self);
        if (current) gst_caps_unref(current);
        break;
    }
    default:
        break;
    }
    return GST_BASE_TRANSFORM_CLASS(gst_home_stab_parent_class)->sink_event(trans, event);
}

/* The frame duration the hold is counted in: the framerate's, else the last buffer's. */
static GstClockTime frame_duration(GstHomeStab *self)
{
    const GstVideoInfo *info = &GST_VIDEO_FILTER(self)->in_info;
    if (GST_VIDEO_INFO_FPS_N(info) > 0 && GST_VIDEO_INFO_FPS_D(info) > 0)
        return gst_util_uint64_scale_int(GST_SECOND, GST_VIDEO_INFO_FPS_D(info), GST_VIDEO_INFO_FPS_N(info));
    return GST_CLOCK_TIME_IS_VALID(self->last_duration) ? self->last_duration : 0;
}

static gboolean gst_home_stab_query(GstBaseTransform *trans, GstPadDirection direction, GstQuery *query)
{
    GstHomeStab *self = GST_HOME_STAB(trans);
    gboolean res = GST_BASE_TRANSFORM_CLASS(gst_home_stab_parent_class)->query(trans, direction, query);
    if (res && direction == GST_PAD_SRC && GST_QUERY_TYPE(query) == GST_QUERY_LATENCY) {
        gboolean live;
        GstClockTime min, max, ours;
        gint lookahead;
        GST_OBJECT_LOCK(self);
        lookahead = self->lookahead;
        GST_OBJECT_UNLOCK(self);
        ours = (GstClockTime)lookahead * frame_duration(self);
        gst_query_parse_latency(query, &live, &min, &max);
        min += ours;
        if (GST_CLOCK_TIME_IS_VALID(max)) max += ours;
        gst_query_set_latency(query, live, min, max);
        GST_DEBUG_OBJECT(self, "latency: %d frames, %" GST_TIME_FORMAT " added", lookahead, GST_TIME_ARGS(ours));
    }
    return res;
}

static gboolean gst_home_stab_stop(GstBaseTransform *trans)
{
    release_all(GST_HOME_STAB(trans));
    return TRUE;
}

static void gst_home_stab_cut(GstHomeStab *self)
{
    GST_OBJECT_LOCK(self);
    self->cut_requested = TRUE;
    GST_OBJECT_UNLOCK(self);
}

static void gst_home_stab_set_property(GObject *object, guint prop_id, const GValue *value, GParamSpec *pspec)
{
    GstHomeStab *self = GST_HOME_STAB(object);
    gboolean settings = TRUE;
    GST_OBJECT_LOCK(self);
    switch (prop_id) {
    case PROP_LOOKAHEAD: self->lookahead = g_value_get_int(value); break;
    case PROP_MARGIN: self->margin = g_value_get_float(value); break;
    case PROP_MARGIN_X: self->margin_x = g_value_get_float(value); break;
    case PROP_MARGIN_Y: self->margin_y = g_value_get_float(value); break;
    case PROP_SMOOTHING: self->smoothing = g_value_get_float(value); break;
    case PROP_EASE: self->ease = g_value_get_float(value); break;
    case PROP_DOWNSCALE: self->downscale = g_value_get_int(value); break;
    case PROP_KEYPOINTS: self->keypoints = g_value_get_int(value); break;
    case PROP_REFINE: self->refine = g_value_get_boolean(value); break;
    case PROP_REFINE_FINEST: self->refine_finest = g_value_get_int(value); break;
    case PROP_HOUGH_DOWNSCALE: self->hough_downscale = g_value_get_int(value); break;
    case PROP_THETA_BINS: self->theta_bins = g_value_get_int(value); break;
    case PROP_POST_MESSAGES: self->post_messages = g_value_get_boolean(value); settings = FALSE; break;
    case PROP_THREADS: self->threads = g_value_get_int(value); settings = FALSE; break;   /* at the next warp */
    default: settings = FALSE; G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec); break;
    }
    if (settings) self->settings_changed = TRUE;
    GST_OBJECT_UNLOCK(self);
}

static void gst_home_stab_get_property(GObject *object, guint prop_id, GValue *value, GParamSpec *pspec)
{
    GstHomeStab *self = GST_HOME_STAB(object);
    GST_OBJECT_LOCK(self);
    switch (prop_id) {
    case PROP_LOOKAHEAD: g_value_set_int(value, self->lookahead); break;
    case PROP_MARGIN: g_value_set_float(value, self->margin); break;
    case PROP_MARGIN_X: g_value_set_float(value, self->margin_x); break;
    case PROP_MARGIN_Y: g_value_set_float(value, self->margin_y); break;
    case PROP_SMOOTHING: g_value_set_float(value, self->smoothing); break;
    case PROP_EASE: g_value_set_float(value, self->ease); break;
    case PROP_DOWNSCALE: g_value_set_int(value, self->downscale); break;
    case PROP_KEYPOINTS: g_value_set_int(value, self->keypoints); break;
    case PROP_REFINE: g_value_set_boolean(value, self->refine); break;
    case PROP_REFINE_FINEST: g_value_set_int(value, self->refine_finest); break;
    case PROP_HOUGH_DOWNSCALE: g_value_set_int(value, self->hough_downscale); break;
    case PROP_THETA_BINS: g_value_set_int(value, self->theta_bins); break;
    case PROP_POST_MESSAGES: g_value_set_boolean(value, self->post_messages); break;
    case PROP_THREADS: g_value_set_int(value, self->threads); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec); break;
    }
    GST_OBJECT_UNLOCK(self);
}

static void gst_home_stab_finalize(GObject *object)
{
    release_all(GST_HOME_STAB(object));
    G_OBJECT_CLASS(gst_home_stab_parent_class)->finalize(object);
}

/* The library's defaults (frame-size independent ones; downscale's depends on the width). */
static home_stab_config library_defaults(void)
{
    home_stab_config d;
    home_stab_default_config(&d, 640, 360);
    return d;
}

static void gst_home_stab_init(GstHomeStab *self)
{
    home_stab_config d = library_defaults();
    self->lookahead = d.lookahead;
    self->margin = d.margin_x;
    self->margin_x = self->margin_y = -1.0f;
    self->smoothing = d.smoothing;
    self->ease = d.ease;
    self->downscale = 0;
    self->keypoints = d.keypoints_per_sign;
    self->refine = d.refine != 0;
    self->refine_finest = d.refine_finest_level;
    self->hough_downscale = d.hough_downscale;
    self->theta_bins = d.theta_bins;
    self->last_duration = GST_CLOCK_TIME_NONE;
    self->threads = 1;
    /* every frame is registered to the one before: a frame dropped for lateness would be a
     * motion the path never sees */
    gst_base_transform_set_qos_enabled(GST_BASE_TRANSFORM(self), FALSE);
}

static void gst_home_stab_class_init(GstHomeStabClass *klass)
{
    GObjectClass *gobject_class = G_OBJECT_CLASS(klass);
    GstElementClass *element_class = GST_ELEMENT_CLASS(klass);
    GstBaseTransformClass *trans_class = GST_BASE_TRANSFORM_CLASS(klass);
    GstVideoFilterClass *filter_class = GST_VIDEO_FILTER_CLASS(klass);
    const GParamFlags rw = G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_PLAYING;
    home_stab_config d = library_defaults();

    gobject_class->set_property = gst_home_stab_set_property;
    gobject_class->get_property = gst_home_stab_get_property;
    gobject_class->finalize = gst_home_stab_finalize;

    g_object_class_install_property(gobject_class, PROP_LOOKAHEAD,
        g_param_spec_int("lookahead", "Lookahead",
                         "Frames of latency for fixed-lag smoothing (0 = causal); the LATENCY query "
                         "adds lookahead x frame duration",
                         0, HOME_STAB_MAX_LOOKAHEAD, d.lookahead, rw));
    g_object_class_install_property(gobject_class, PROP_MARGIN,
        g_param_spec_float("margin", "Margin",
                           "Crop margin per side, fraction of the frame (both axes unless margin-x "
                           "or margin-y is set)", 0.0f, 0.4f, d.margin_x, rw));
    g_object_class_install_property(gobject_class, PROP_MARGIN_X,
        g_param_spec_float("margin-x", "Horizontal margin",
                           "Left and right crop margin, fraction of the width (-1 = margin); "
                           "unequal margins change the picture's aspect", -1.0f, 0.4f, -1.0f, rw));
    g_object_class_install_property(gobject_class, PROP_MARGIN_Y,
        g_param_spec_float("margin-y", "Vertical margin",
                           "Top and bottom crop margin, fraction of the height (-1 = margin)",
                           -1.0f, 0.4f, -1.0f, rw));
    g_object_class_install_property(gobject_class, PROP_SMOOTHING,
        g_param_spec_float("smoothing", "Smoothing",
                           "Path smoothing time constant in frames, 1..1000; 0 = automatic "
                           "(lookahead / 2, at least 3; 15 with a lookahead below 5)",
                           0.0f, 1000.0f, d.smoothing, rw));
    g_object_class_install_property(gobject_class, PROP_EASE,
        g_param_spec_float("ease", "Ease",
                           "With a lookahead: share of the pan given up at a stream's ends, 0 (keep "
                           "panning) .. 1 (start from and come to rest)", 0.0f, 1.0f, d.ease, rw));
    g_object_class_install_property(gobject_class, PROP_DOWNSCALE,
        g_param_spec_int("downscale", "Downscale",
                         "Register on luma box-averaged by 1, 2 or 4; 0 = automatic (2 above 960 px "
                         "wide, else 1)", 0, 4, 0, rw));
    g_object_class_install_property(gobject_class, PROP_KEYPOINTS,
        g_param_spec_int("keypoints", "Keypoints", "HOME keypoints per sign and frame",
                         16, HOME_MAX_KEYPOINTS_PER_SIGN, d.keypoints_per_sign, rw));
    g_object_class_install_property(gobject_class, PROP_REFINE,
        g_param_spec_boolean("refine", "Refine",
                             "HOME's photometric refinement of each registration", d.refine != 0, rw));
    g_object_class_install_property(gobject_class, PROP_REFINE_FINEST,
        g_param_spec_int("refine-finest", "Finest refinement level",
                         "End the refinement at full (0) or half (1) size of the registration image",
                         0, 1, d.refine_finest_level, rw));
    g_object_class_install_property(gobject_class, PROP_HOUGH_DOWNSCALE,
        g_param_spec_int("hough-downscale", "Hough downscale",
                         "HOME's Hough transform on the registration image (1) or its 1/2 or 1/4 size "
                         "copy (2, 4); 0 = automatic (the copy about 160 px wide)", 0, 4, d.hough_downscale, rw));
    g_object_class_install_property(gobject_class, PROP_THETA_BINS,
        g_param_spec_int("theta-bins", "Theta bins",
                         "HOME's theta bins, 16.." G_STRINGIFY(HOME_MAX_THETA_BINS) "; 0 = automatic (88)",
                         0, HOME_MAX_THETA_BINS, d.theta_bins, rw));
    g_object_class_install_property(gobject_class, PROP_POST_MESSAGES,
        g_param_spec_boolean("post-messages", "Post messages",
                             "Post an element message \"homestab\" per output frame with its raw and "
                             "smoothed camera path and motion status", FALSE, rw));

    g_object_class_install_property(gobject_class, PROP_THREADS,
        g_param_spec_int("threads", "Threads",
                         "Threads for the warp, in row bands, the streaming thread counted (the same "
                         "bytes for any count); 0 = the online CPUs, at most " G_STRINGIFY(EIS_POOL_AUTO_MAX),
                         0, EIS_POOL_MAX_THREADS, 1, rw));

    /* Declare a scene cut before the next frame (an edit or a stream switch the application
     * knows of): the path restarts there, nothing held is lost. */
    home_stab_signals[SIGNAL_CUT] = g_signal_new_class_handler(
        "cut", G_TYPE_FROM_CLASS(klass), G_SIGNAL_RUN_LAST | G_SIGNAL_ACTION,
        G_CALLBACK(gst_home_stab_cut), NULL, NULL, NULL, G_TYPE_NONE, 0);

    gst_element_class_set_static_metadata(element_class, "HOME video stabiliser", "Filter/Effect/Video",
        "Electronic image stabilisation with libhome: Hough-space registration, a smoothed camera "
        "path with optional lookahead, and a crop window that never leaves the frame",
        "libhome");
    gst_element_class_add_static_pad_template(element_class, &sink_template);
    gst_element_class_add_static_pad_template(element_class, &src_template);

    trans_class->submit_input_buffer = GST_DEBUG_FUNCPTR(gst_home_stab_submit_input_buffer);
    trans_class->generate_output = GST_DEBUG_FUNCPTR(gst_home_stab_generate_output);
    trans_class->sink_event = GST_DEBUG_FUNCPTR(gst_home_stab_sink_event);
    trans_class->query = GST_DEBUG_FUNCPTR(gst_home_stab_query);
    trans_class->stop = GST_DEBUG_FUNCPTR(gst_home_stab_stop);
    filter_class->set_info = GST_DEBUG_FUNCPTR(gst_home_stab_set_info);
    filter_class->transform_frame = GST_DEBUG_FUNCPTR(gst_home_stab_transform_frame);
}

static gboolean plugin_init(GstPlugin *plugin)
{
    GST_DEBUG_CATEGORY_INIT(home_stab_debug, "homestab", 0, "libhome video stabiliser");
    return gst_element_register(plugin, "homestab", GST_RANK_NONE, GST_TYPE_HOME_STAB);
}

GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, home,
                  "Video stabilisation with libhome (HOME registration)", plugin_init,
                  GST_HOME_STAB_VERSION, GST_LICENSE_UNKNOWN, "libhome", "libhome examples/gst")
