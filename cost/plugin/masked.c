/*
 * Masked stretches on a Cortex-M (QEMU TCG plugin, API version 1, as in Debian 12's QEMU 7.2,
 * which ships no plugins and no plugin header).
 *
 * Counts the guest instructions run while interrupts are masked, two ways, and reports the
 * longest stretch of each and where it began:
 *
 * - "primask": from the instruction that sets PRIMASK while it is clear to the one that clears
 *   it. This is what delays an interrupt. PRIMASK is modelled from the instructions that change
 *   it, as the architecture has it (exception entry and return leave it alone): `cpsid i` sets
 *   it, `cpsie i` clears it, and `msr primask, rN` writes what rN holds. API version 1 cannot
 *   read registers, so that value is taken from the matching `mrs rX, primask`: critical
 *   sections save PRIMASK that way on entry and write it back on exit (cortex-m's
 *   `critical-section-single-core` and `interrupt::free`), strictly nested, so every `mrs`
 *   pushes the modelled PRIMASK on a stack and every `msr` pops it. An `msr` with nothing to pop
 *   (an image that writes PRIMASK from anything else) is taken as clearing it and counted
 *   ("unmatched-msr"); a read that is never written back would shift the pairs, which the
 *   counts show as well ("saved" left on the stack at exit).
 * - "basepri": from the instruction that raises BASEPRI while it is clear to the one that puts it
 *   back clear: the firmware's critical sections (src/critical.rs) mask every interrupt but the
 *   pulse interrupt so, with `mrs rX, basepri` to save it, `msr basepri_max, rN` to raise it
 *   and `msr basepri, rX` to put it back; the same pairing as PRIMASK's models it (a raise
 *   counts as masking, a write back takes the value its `mrs` saved).
 * - "section": from entering the outermost critical section to leaving it, given the entry
 *   addresses of the `critical-section` crate's `_critical_section_1_0_acquire` and `..._release`
 *   (arguments `acquire=` and `release=`): acquires and releases are counted in pairs, the
 *   stretch ends at the release that closes the first acquire.
 *
 * A stretch began at an instruction (the `cpsid i`, or the acquire's entry) and was reached
 * through a call: the last `bl`/`blx` run before it (for the acquire, the call of it; for a
 * `cpsid i` inside a function the acquire's caller, or the last call made before an inlined
 * one). At exit the plugin writes one line per kind and per place a stretch began, the longest
 * and the number of stretches there:
 *
 *     stretch <kind> <begin address> <call address> <longest> <count>
 *
 * then "unmatched-msr <count>", "saved <depth>", "open <kind> <begin address> <instructions so far>" for a stretch
 * still masked at exit, and "total <instructions>". The runner (count.py) names the addresses.
 *
 * Build: gcc -O2 -shared -fPIC -o masked.so masked.c
 * Run:   qemu-system-arm ... -plugin ./masked.so,acquire=0x1234,release=0x1256 -d plugin -D masked.txt
 */
#include <inttypes.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The few declarations of qemu-plugin.h (API version 1) this plugin uses. */
typedef uint64_t qemu_plugin_id_t;
typedef struct qemu_info_t qemu_info_t;
struct qemu_plugin_tb;
struct qemu_plugin_insn;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_CB_R_REGS, QEMU_PLUGIN_CB_RW_REGS };
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 };
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void *userdata);
void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *tb, size_t idx);
uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *insn);
const void *qemu_plugin_insn_data(const struct qemu_plugin_insn *insn);
size_t qemu_plugin_insn_size(const struct qemu_plugin_insn *insn);
void qemu_plugin_register_vcpu_insn_exec_inline(struct qemu_plugin_insn *insn, enum qemu_plugin_op op,
                                                void *ptr, uint64_t imm);
void qemu_plugin_register_vcpu_insn_exec_cb(struct qemu_plugin_insn *insn, qemu_plugin_vcpu_udata_cb_t cb,
                                            enum qemu_plugin_cb_flags flags, void *userdata);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void *userdata);
void qemu_plugin_outs(const char *string);

__attribute__((visibility("default"))) int qemu_plugin_version = 1;

/* Thumb encodings: CPS (16 bits) is 1011 0110 011m 0aif, m set for CPSID; BL is 11110... then
 * 11x1...; BLX register is 0100 0111 1xxx x000; MSR to a special register is 1111 0011 1000
 * nnnn then 1000 mm00 SYSm, and MRS 1111 0011 1110 1111 then 1000 dddd SYSm; SYSm 16 is
 * PRIMASK. */
#define CPS_MASK 0xffe8u
#define CPS 0xb660u
#define CPS_DISABLE 0x0010u
#define CPS_I 0x0002u
#define BL_FIRST_MASK 0xf800u
#define BL_FIRST 0xf000u
#define BL_SECOND_MASK 0xd000u
#define BL_SECOND 0xd000u
#define BLX_REG_MASK 0xff87u
#define BLX_REG 0x4780u
#define MSR_FIRST_MASK 0xfff0u
#define MSR_FIRST 0xf380u
#define MSR_SECOND_MASK 0xf3ffu
#define MSR_PRIMASK_SECOND 0x8010u
#define MRS_FIRST 0xf3efu
#define MRS_SECOND_MASK 0xf0ffu
#define MRS_PRIMASK_SECOND 0x8010u
/* SYSm 17 is BASEPRI, 18 BASEPRI_MAX. */
#define MSR_BASEPRI_SECOND 0x8011u
#define MSR_BASEPRI_MAX_SECOND 0x8012u
#define MRS_BASEPRI_SECOND 0x8011u
/* PRIMASK values saved by `mrs` and not yet written back: deeper than any nesting of critical
 * sections. */
#define SAVED_MAX 256

enum kind { KIND_PRIMASK, KIND_BASEPRI, KIND_SECTION, KINDS };
static const char *const kind_names[KINDS] = {"primask", "basepri", "section"};

/* Where stretches began: a small open-addressing table, keyed by kind, address and call. */
#define SITES 4096
struct site {
    bool used;
    enum kind kind;
    uint64_t begin;
    uint64_t call;
    uint64_t longest;
    uint64_t count;
};
static struct site sites[SITES];
static bool sites_full;

/* A stretch under way. */
struct open_stretch {
    bool open;
    uint64_t since;
    uint64_t begin;
    uint64_t call;
};

static uint64_t insn_count;
static uint64_t acquire_addr = UINT64_MAX;
static uint64_t release_addr = UINT64_MAX;
static uint64_t last_call = UINT64_MAX;
/* The call that entered the acquire, for the `cpsid i` inside it. */
static uint64_t acquire_call = UINT64_MAX;
static bool in_acquire;
static struct open_stretch stretches[KINDS];
static uint64_t section_depth;
/* A mask modelled from the instructions that write it (PRIMASK, BASEPRI): whether it masks, and
 * the values saved by `mrs` not yet written back by `msr`. */
struct mask {
    enum kind kind;
    bool masked;
    bool saved[SAVED_MAX];
    size_t saved_depth;
};
static struct mask primask = {KIND_PRIMASK};
static struct mask basepri = {KIND_BASEPRI};
static uint64_t saved_dropped;
static uint64_t unmatched_msr;

static uint16_t halfword(const uint8_t *p)
{
    return (uint16_t)(p[0] | p[1] << 8);
}

static void record(enum kind kind, const struct open_stretch *s)
{
    uint64_t n = insn_count - s->since;
    size_t h = (size_t)((s->begin * 0x9e3779b97f4a7c15ull) ^ (s->call * 0xc2b2ae3d27d4eb4full) ^ kind) % SITES;
    for (size_t probe = 0; probe < SITES; probe++) {
        struct site *e = &sites[(h + probe) % SITES];
        if (!e->used) {
            *e = (struct site){true, kind, s->begin, s->call, n, 1};
            return;
        }
        if (e->kind == kind && e->begin == s->begin && e->call == s->call) {
            e->count++;
            if (n > e->longest) {
                e->longest = n;
            }
            return;
        }
    }
    sites_full = true;
}

static void on_call(unsigned int vcpu_index, void *userdata)
{
    (void)vcpu_index;
    last_call = (uint64_t)(uintptr_t)userdata;
}

/* A mask set (at `at`) or cleared: a stretch begins or ends. */
static void set_mask(struct mask *m, bool masked, uint64_t at)
{
    struct open_stretch *s = &stretches[m->kind];
    if (masked && !m->masked) {
        *s = (struct open_stretch){true, insn_count, at, in_acquire ? acquire_call : last_call};
    } else if (!masked && m->masked && s->open) {
        record(m->kind, s);
        s->open = false;
    }
    m->masked = masked;
}

/* `mrs`: the mask's value saved. */
static void save_mask(struct mask *m)
{
    if (m->saved_depth == SAVED_MAX) {
        /* The oldest is lost: keep the newest, which the next writes pair with. */
        memmove(m->saved, m->saved + 1, sizeof m->saved - sizeof m->saved[0]);
        m->saved_depth--;
        saved_dropped++;
    }
    m->saved[m->saved_depth++] = m->masked;
}

/* `msr` of a saved value: the mask put back. */
static void restore_mask(struct mask *m, uint64_t at)
{
    bool value = false;
    if (m->saved_depth > 0) {
        value = m->saved[--m->saved_depth];
    } else {
        unmatched_msr++;
    }
    set_mask(m, value, at);
}

static void on_cpsid(unsigned int vcpu_index, void *userdata)
{
    (void)vcpu_index;
    set_mask(&primask, true, (uint64_t)(uintptr_t)userdata);
    in_acquire = false;
}

static void on_cpsie(unsigned int vcpu_index, void *userdata)
{
    (void)vcpu_index;
    set_mask(&primask, false, (uint64_t)(uintptr_t)userdata);
}

static void on_mrs_primask(unsigned int vcpu_index, void *userdata)
{
    (void)vcpu_index;
    (void)userdata;
    save_mask(&primask);
}

static void on_msr_primask(unsigned int vcpu_index, void *userdata)
{
    (void)vcpu_index;
    restore_mask(&primask, (uint64_t)(uintptr_t)userdata);
}

static void on_mrs_basepri(unsigned int vcpu_index, void *userdata)
{
    (void)vcpu_index;
    (void)userdata;
    save_mask(&basepri);
}

static void on_msr_basepri(unsigned int vcpu_index, void *userdata)
{
    (void)vcpu_index;
    restore_mask(&basepri, (uint64_t)(uintptr_t)userdata);
}

static void on_msr_basepri_max(unsigned int vcpu_index, void *userdata)
{
    (void)vcpu_index;
    set_mask(&basepri, true, (uint64_t)(uintptr_t)userdata);
    in_acquire = false;
}

static void on_acquire(unsigned int vcpu_index, void *userdata)
{
    struct open_stretch *s = &stretches[KIND_SECTION];
    (void)vcpu_index;
    (void)userdata;
    in_acquire = true;
    acquire_call = last_call;
    if (section_depth++ == 0) {
        *s = (struct open_stretch){true, insn_count, acquire_addr, last_call};
    }
}

static void on_release(unsigned int vcpu_index, void *userdata)
{
    struct open_stretch *s = &stretches[KIND_SECTION];
    (void)vcpu_index;
    (void)userdata;
    if (section_depth == 0) {
        return;
    }
    if (--section_depth == 0 && s->open) {
        record(KIND_SECTION, s);
        s->open = false;
    }
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    size_t n = qemu_plugin_tb_n_insns(tb);
    (void)id;
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        uint64_t vaddr = qemu_plugin_insn_vaddr(insn);
        void *at = (void *)(uintptr_t)vaddr;
        const uint8_t *code = qemu_plugin_insn_data(insn);
        size_t size = qemu_plugin_insn_size(insn);
        uint16_t first = size >= 2 ? halfword(code) : 0;
        uint16_t second = size >= 4 ? halfword(code + 2) : 0;
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &insn_count, 1);
        if (vaddr == acquire_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_acquire, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
        if (vaddr == release_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_release, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
        if (size == 2 && (first & CPS_MASK) == CPS && (first & CPS_I)) {
            qemu_plugin_vcpu_udata_cb_t cb = (first & CPS_DISABLE) ? on_cpsid : on_cpsie;
            qemu_plugin_register_vcpu_insn_exec_cb(insn, cb, QEMU_PLUGIN_CB_NO_REGS, at);
        } else if ((size == 4 && (first & BL_FIRST_MASK) == BL_FIRST && (second & BL_SECOND_MASK) == BL_SECOND) ||
                   (size == 2 && (first & BLX_REG_MASK) == BLX_REG)) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_call, QEMU_PLUGIN_CB_NO_REGS, at);
        } else if (size == 4 && (first & MSR_FIRST_MASK) == MSR_FIRST && (second & MSR_SECOND_MASK) == MSR_PRIMASK_SECOND) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_msr_primask, QEMU_PLUGIN_CB_NO_REGS, at);
        } else if (size == 4 && first == MRS_FIRST && (second & MRS_SECOND_MASK) == MRS_PRIMASK_SECOND) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_mrs_primask, QEMU_PLUGIN_CB_NO_REGS, NULL);
        } else if (size == 4 && (first & MSR_FIRST_MASK) == MSR_FIRST && (second & MSR_SECOND_MASK) == MSR_BASEPRI_SECOND) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_msr_basepri, QEMU_PLUGIN_CB_NO_REGS, at);
        } else if (size == 4 && (first & MSR_FIRST_MASK) == MSR_FIRST &&
                   (second & MSR_SECOND_MASK) == MSR_BASEPRI_MAX_SECOND) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_msr_basepri_max, QEMU_PLUGIN_CB_NO_REGS, at);
        } else if (size == 4 && first == MRS_FIRST && (second & MRS_SECOND_MASK) == MRS_BASEPRI_SECOND) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_mrs_basepri, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
    }
}

static void on_plugin_exit(qemu_plugin_id_t id, void *userdata)
{
    char line[160];
    (void)id;
    (void)userdata;
    for (size_t i = 0; i < SITES; i++) {
        const struct site *e = &sites[i];
        if (e->used) {
            snprintf(line, sizeof line, "stretch %s 0x%" PRIx64 " 0x%" PRIx64 " %" PRIu64 " %" PRIu64 "\n",
                     kind_names[e->kind], e->begin, e->call, e->longest, e->count);
            qemu_plugin_outs(line);
        }
    }
    for (int k = 0; k < KINDS; k++) {
        const struct open_stretch *s = &stretches[k];
        if (s->open) {
            snprintf(line, sizeof line, "open %s 0x%" PRIx64 " %" PRIu64 "\n", kind_names[k], s->begin,
                     insn_count - s->since);
            qemu_plugin_outs(line);
        }
    }
    if (sites_full) {
        qemu_plugin_outs("sites-full\n");
    }
    snprintf(line, sizeof line, "unmatched-msr %" PRIu64 "\nsaved %zu %" PRIu64 "\ntotal %" PRIu64 "\n", unmatched_msr,
             primask.saved_depth + basepri.saved_depth, saved_dropped, insn_count);
    qemu_plugin_outs(line);
}

__attribute__((visibility("default"))) int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info,
                                                              int argc, char **argv)
{
    (void)info;
    for (int i = 0; i < argc; i++) {
        if (strncmp(argv[i], "acquire=", 8) == 0) {
            acquire_addr = strtoull(argv[i] + 8, NULL, 0);
        } else if (strncmp(argv[i], "release=", 8) == 0) {
            release_addr = strtoull(argv[i] + 8, NULL, 0);
        } else {
            fprintf(stderr, "masked: unknown argument %s\n", argv[i]);
            return -1;
        }
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    qemu_plugin_register_atexit_cb(id, on_plugin_exit, NULL);
    return 0;
}
