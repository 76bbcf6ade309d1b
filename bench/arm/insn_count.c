/* qemu TCG plugin (qemu 7.2's plugin API, version 1): executed guest instructions per
 * translated block, for bench/arm/count.sh.
 *   qemu-aarch64 -plugin libinsn_count.so,out=FILE[,mark=ADDR] PROGRAM ...
 * At exit FILE gets one line per block start address: "vaddr n_insns executions l2_misses" (hex
 * vaddr; misses only in the working-set mode);
 * the report maps addresses to functions and objects with the program's symbols and link map.
 * Counting is an inline add per block execution (cheap; not atomic, so count one thread).
 * With mark=ADDR (the hex address of a function the program calls once per frame) it also
 * records, between two calls, the distinct 64-byte lines loaded or stored (the working set), the
 * bytes accessed, and the misses of a model of the Cortex-A72's L2 (Raspberry Pi 4: 1 MiB,
 * 16 ways, 64-byte lines; here LRU, fed every access: no L1 in front, no prefetcher; l2kb=N
 * sets another size), which keeps its contents from frame to frame. FILE.frames gets one
 * "frame LINES BYTES MISSES" line per call, plus the rest after the last.
 * Built against qemu's include/qemu/qemu-plugin.h (bench/arm/qemu_plugin_h.sh). */
#include <qemu-plugin.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

QEMU_PLUGIN_EXPORT int qemu_plugin_version = QEMU_PLUGIN_VERSION;

/* a translated block: its executions, and in the working-set mode the L2 model's misses of its
 * loads and stores */
typedef struct block { uint64_t vaddr, n, execs, misses; struct block *next; } block;

#define BLOCK_BUCKETS (1u << 16)
static block *buckets[BLOCK_BUCKETS];
static char out_path[4096];
static uint64_t mark_addr;

/* the working-set mode: an open-addressing set of line numbers, cleared at each mark */
static uint64_t *lines;
static size_t lines_cap, lines_used;
static uint64_t bytes_accessed;
static FILE *frames_out;

/* the L2 model: sets x L2_WAYS tags (line + 1, 0 = empty) with the access clock of each */
#define L2_WAYS 16
static uint64_t *l2_tag, *l2_used, l2_clock, l2_misses;
static size_t l2_sets;

/* 1 on a miss */
static int l2_access(uint64_t line)
{
    uint64_t *tag = l2_tag + (line & (l2_sets - 1)) * L2_WAYS;
    uint64_t *used = l2_used + (line & (l2_sets - 1)) * L2_WAYS;
    int w, victim = 0;
    l2_clock++;
    for (w = 0; w < L2_WAYS; w++) {
        if (tag[w] == line + 1) { used[w] = l2_clock; return 0; }
        if (used[w] < used[victim]) victim = w;
    }
    l2_misses++;
    tag[victim] = line + 1;
    used[victim] = l2_clock;
    return 1;
}

static block *block_for(uint64_t vaddr, uint64_t n)
{
    unsigned h = (unsigned)((vaddr >> 2) * 2654435761u) & (BLOCK_BUCKETS - 1);
    block *b;
    for (b = buckets[h]; b; b = b->next)
        if (b->vaddr == vaddr && b->n == n) return b;
    b = calloc(1, sizeof *b);
    if (!b) abort();
    b->vaddr = vaddr;
    b->n = n;
    b->next = buckets[h];
    buckets[h] = b;
    return b;
}

static void line_insert(uint64_t line)
{
    size_t i;
    if (2 * (lines_used + 1) > lines_cap) { /* grow: rehash into twice the slots */
        size_t old = lines_cap, k;
        uint64_t *prev = lines;
        lines_cap = old ? 2 * old : (1u << 16);
        lines = calloc(lines_cap, sizeof *lines);
        if (!lines) abort();
        lines_used = 0;
        for (k = 0; k < old; k++)
            if (prev[k]) line_insert(prev[k] - 1);
        free(prev);
    }
    i = (size_t)((line * 0x9E3779B97F4A7C15ull) >> 20) & (lines_cap - 1);
    while (lines[i]) {
        if (lines[i] == line + 1) return;
        i = (i + 1) & (lines_cap - 1);
    }
    lines[i] = line + 1; /* 0 marks an empty slot */
    lines_used++;
}

static void on_mem(unsigned int vcpu, qemu_plugin_meminfo_t info, uint64_t vaddr, void *udata)
{
    unsigned size = 1u << qemu_plugin_mem_size_shift(info);
    uint64_t l;
    (void)vcpu;
    bytes_accessed += size;
    for (l = vaddr >> 6; l <= (vaddr + size - 1) >> 6; l++) {
        line_insert(l);
        ((block *)udata)->misses += (uint64_t)l2_access(l);
    }
}

static void frame_done(void)
{
    fprintf(frames_out, "frame %zu %llu %llu\n", lines_used, (unsigned long long)bytes_accessed,
            (unsigned long long)l2_misses);
    if (lines) memset(lines, 0, lines_cap * sizeof *lines);
    lines_used = 0;
    bytes_accessed = 0;
    l2_misses = 0;
}

static void on_mark(unsigned int vcpu, void *udata)
{
    (void)vcpu;
    (void)udata;
    frame_done();
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    uint64_t vaddr = qemu_plugin_tb_vaddr(tb);
    size_t n = qemu_plugin_tb_n_insns(tb), i;
    block *b = block_for(vaddr, n);
    (void)id;
    qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &b->execs, 1);
    if (!mark_addr) return;
    if (vaddr == mark_addr)
        qemu_plugin_register_vcpu_tb_exec_cb(tb, on_mark, QEMU_PLUGIN_CB_NO_REGS, NULL);
    for (i = 0; i < n; i++)
        qemu_plugin_register_vcpu_mem_cb(qemu_plugin_tb_get_insn(tb, i), on_mem,
                                         QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_MEM_RW, b);
}

static void at_exit(qemu_plugin_id_t id, void *udata)
{
    FILE *f = fopen(out_path, "w");
    unsigned h;
    (void)id;
    (void)udata;
    if (!f) { perror(out_path); return; }
    for (h = 0; h < BLOCK_BUCKETS; h++) {
        const block *b;
        for (b = buckets[h]; b; b = b->next)
            if (b->execs)
                fprintf(f, "%llx %llu %llu %llu\n", (unsigned long long)b->vaddr,
                        (unsigned long long)b->n, (unsigned long long)b->execs,
                        (unsigned long long)b->misses);
    }
    fclose(f);
    if (frames_out) { frame_done(); fclose(frames_out); }
}

QEMU_PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc,
                                           char **argv)
{
    int i;
    unsigned long l2_kb = 1024;
    (void)info;
    for (i = 0; i < argc; i++) {
        if (!strncmp(argv[i], "out=", 4)) snprintf(out_path, sizeof out_path, "%s", argv[i] + 4);
        else if (!strncmp(argv[i], "mark=", 5)) mark_addr = strtoull(argv[i] + 5, NULL, 16);
        else if (!strncmp(argv[i], "l2kb=", 5)) l2_kb = strtoul(argv[i] + 5, NULL, 10);
        else { fprintf(stderr, "insn_count: unknown option %s\n", argv[i]); return -1; }
    }
    if (!out_path[0]) { fprintf(stderr, "insn_count: needs out=FILE\n"); return -1; }
    if (mark_addr) {
        char path[4200];
        snprintf(path, sizeof path, "%s.frames", out_path);
        frames_out = fopen(path, "w");
        if (!frames_out) { perror(path); return -1; }
        l2_sets = l2_kb * 1024 / 64 / L2_WAYS;
        if (l2_sets < 1 || (l2_sets & (l2_sets - 1))) {
            fprintf(stderr, "insn_count: l2kb must give a power-of-two number of sets\n");
            return -1;
        }
        l2_tag = calloc(l2_sets * L2_WAYS, sizeof *l2_tag);
        l2_used = calloc(l2_sets * L2_WAYS, sizeof *l2_used);
        if (!l2_tag || !l2_used) return -1;
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    qemu_plugin_register_atexit_cb(id, at_exit, NULL);
    return 0;
}
