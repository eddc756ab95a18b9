/*
 * Instruction and cycle counter for the Cortex-M4F cost benchmark (QEMU TCG plugin, API version
 * 1, as in Debian 12's QEMU 7.2, which ships no plugins and no plugin header).
 *
 * Every guest instruction adds one to a counter and one to the counter of its kind (inline, so
 * counting is exact and cheap). The kinds are those of the Cortex-M4 Technical Reference
 * Manual's instruction timings (Table 3-1, and Table 7-1 for the FPU): the runner (count.py)
 * holds the cycles of each kind and turns the counts into time. Each kind is decided once, when
 * QEMU translates the instruction, from its disassembly (QEMU's capstone), and so is what
 * depends on its neighbours in the same translated block: a load or store right after another
 * one pipelines with it, an IT right after a 16-bit instruction folds into it.
 *
 * What only the run can tell is counted as it happens: a branch taken (the next block does not
 * start where the last one ended, so the pipeline refills), a taken branch whose target is not
 * in a model of the STM32F407's ART instruction cache (64 lines of 128 bits, least recently
 * used out; sequential code comes through the prefetch buffer and is not cached, as RM0090
 * says), and a load from flash not in a model of its data cache (8 lines of 128 bits).
 *
 * Each time the instruction at address `mark` executes, every counter is written out as a line
 * "mark <instructions> <kind counts...> <words> <taken> <imiss> <dmiss>": the harness calls its
 * marker function between the pieces of work it measures, and the difference of two marks is
 * exactly what ran between them. The first line written, "kinds <names...>", names the kinds.
 * With `profile=on`, every translation block's start address, size and execution count are
 * written at exit, so the runner can tell which functions the instructions went to.
 *
 * Build: gcc -O2 -shared -fPIC -o insn_count.so insn_count.c
 * Run:   qemu-system-arm ... -plugin ./insn_count.so,mark=0x1234 -d plugin -D counts.txt
 */
#include <ctype.h>
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
typedef uint32_t qemu_plugin_meminfo_t;
struct qemu_plugin_tb;
struct qemu_plugin_insn;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_CB_R_REGS, QEMU_PLUGIN_CB_RW_REGS };
enum qemu_plugin_mem_rw { QEMU_PLUGIN_MEM_R = 1, QEMU_PLUGIN_MEM_W, QEMU_PLUGIN_MEM_RW };
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 };
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void *userdata);
typedef void (*qemu_plugin_vcpu_mem_cb_t)(unsigned int vcpu_index, qemu_plugin_meminfo_t info, uint64_t vaddr,
                                          void *userdata);
void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
uint64_t qemu_plugin_tb_vaddr(const struct qemu_plugin_tb *tb);
struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *tb, size_t idx);
uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *insn);
size_t qemu_plugin_insn_size(const struct qemu_plugin_insn *insn);
char *qemu_plugin_insn_disas(const struct qemu_plugin_insn *insn);
void qemu_plugin_register_vcpu_insn_exec_inline(struct qemu_plugin_insn *insn, enum qemu_plugin_op op,
                                                void *ptr, uint64_t imm);
void qemu_plugin_register_vcpu_tb_exec_inline(struct qemu_plugin_tb *tb, enum qemu_plugin_op op, void *ptr,
                                              uint64_t imm);
void qemu_plugin_register_vcpu_insn_exec_cb(struct qemu_plugin_insn *insn, qemu_plugin_vcpu_udata_cb_t cb,
                                            enum qemu_plugin_cb_flags flags, void *userdata);
void qemu_plugin_register_vcpu_tb_exec_cb(struct qemu_plugin_tb *tb, qemu_plugin_vcpu_udata_cb_t cb,
                                          enum qemu_plugin_cb_flags flags, void *userdata);
void qemu_plugin_register_vcpu_mem_cb(struct qemu_plugin_insn *insn, qemu_plugin_vcpu_mem_cb_t cb,
                                      enum qemu_plugin_cb_flags flags, enum qemu_plugin_mem_rw rw, void *userdata);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void *userdata);
void qemu_plugin_outs(const char *string);

__attribute__((visibility("default"))) int qemu_plugin_version = 1;

/* The kinds of instructions, as the Cortex-M4 TRM times them; count.py has their cycles. */
enum kind {
    K_ALU,        /* data processing, moves, compares, shifts, bit fields, extends, NOP */
    K_MUL,        /* MUL, MLA, MLS, long multiplies */
    K_DIV,        /* SDIV, UDIV: 2 to 12 cycles */
    K_LOAD,       /* LDR, LDRB, LDRH, LDRSB, LDRSH */
    K_LOAD_PIPE,  /* the same right after another load or store: pipelined */
    K_LOAD_PC,    /* LDR PC: blocking, and a refill */
    K_STORE,      /* STR, STRB, STRH with an immediate offset: the store overlaps what follows */
    K_STORE_REG,  /* the same with a register offset */
    K_PAIR,       /* LDRD, STRD */
    K_MULTI,      /* LDM, STM, PUSH, POP: 1 + N (the registers are counted apart) */
    K_BRANCH,     /* B, BL, BX, BLX, CBZ, CBNZ: 1, and a refill where taken */
    K_TABLE,      /* TBB, TBH: 2, and a refill */
    K_IT,         /* IT on its own */
    K_IT_FOLDED,  /* IT after a 16-bit instruction: folded into it */
    K_BARRIER,    /* DMB, DSB, ISB */
    K_SYSTEM,     /* MRS, MSR, CPSIE, CPSID, WFI, WFE, SEV, BKPT, SVC */
    K_FP,         /* VADD, VSUB, VMUL, VABS, VNEG, VCMP, VCVT, VMOV, VMRS, VMSR */
    K_FP_MAC,     /* VMLA, VMLS, VNMLA, VNMLS, VFMA, VFMS, VFNMA, VFNMS */
    K_FP_DIVSQRT, /* VDIV, VSQRT: 14 */
    K_FP_LOAD,    /* VLDR */
    K_FP_STORE,   /* VSTR */
    K_FP_MULTI,   /* VLDM, VSTM, VPUSH, VPOP: 1 + N words */
    K_OTHER,      /* none of these: count.py charges one cycle and says so */
    KINDS
};
static const char *const KIND_NAMES[KINDS] = {
    "alu",    "mul",    "div",       "load",       "load_pipe",  "load_pc", "store", "store_reg",
    "pair",   "multi",  "branch",    "table",      "it",         "it_folded", "barrier", "system",
    "fp",     "fp_mac", "fp_divsqrt", "fp_load",   "fp_store",   "fp_multi", "other",
};

static uint64_t insn_count;
static uint64_t kind_count[KINDS];
/* Registers (words) moved by LDM/STM/PUSH/POP and VLDM/VSTM/VPUSH/VPOP. */
static uint64_t multi_words;
static uint64_t taken;
static uint64_t icache_misses;
static uint64_t dcache_misses;
static uint64_t mark_addr = UINT64_MAX;
static bool profile;
/* Where the block executed last ends: a block starting elsewhere was reached by a branch. */
static uint64_t last_block_end = UINT64_MAX;
/* Mnemonics of kind K_OTHER, for the exit report. */
static char unknown[16][16];
static int unknown_n;

/* Flash (the model's code region at 0; the F407's at 0x0800_0000) and the ART's caches. */
#define FLASH_END 0x00400000u
#define LINE_SHIFT 4
#define ICACHE_LINES 64
#define DCACHE_LINES 8

struct cache {
    int lines;
    uint64_t tag[ICACHE_LINES];
    uint64_t used[ICACHE_LINES];
    uint64_t clock;
};
static struct cache icache = {.lines = ICACHE_LINES};
static struct cache dcache = {.lines = DCACHE_LINES};

/* Looks the line of `addr` up; true on a miss, which then fills the least recently used line. */
static bool cache_miss(struct cache *c, uint64_t addr)
{
    uint64_t tag = (addr >> LINE_SHIFT) + 1; /* 0 marks an empty line */
    int oldest = 0;
    c->clock++;
    for (int i = 0; i < c->lines; i++) {
        if (c->tag[i] == tag) {
            c->used[i] = c->clock;
            return false;
        }
        if (c->used[i] < c->used[oldest]) {
            oldest = i;
        }
    }
    c->tag[oldest] = tag;
    c->used[oldest] = c->clock;
    return true;
}

/* One translated block, for the branch and cache model and the profile. */
struct block {
    uint64_t vaddr;
    uint64_t end;
    uint64_t n_insns;
    uint64_t executions;
    struct block *next;
};
static struct block *blocks;

static void on_mark(unsigned int vcpu_index, void *userdata)
{
    char line[1024];
    int len;
    (void)vcpu_index;
    (void)userdata;
    len = snprintf(line, sizeof line, "mark %" PRIu64, insn_count);
    for (int k = 0; k < KINDS; k++) {
        len += snprintf(line + len, sizeof line - len, " %" PRIu64, kind_count[k]);
    }
    snprintf(line + len, sizeof line - len, " %" PRIu64 " %" PRIu64 " %" PRIu64 " %" PRIu64 "\n", multi_words, taken,
             icache_misses, dcache_misses);
    qemu_plugin_outs(line);
}

static void on_block(unsigned int vcpu_index, void *userdata)
{
    struct block *b = userdata;
    (void)vcpu_index;
    if (b->vaddr != last_block_end) {
        taken++;
        if (b->vaddr < FLASH_END && cache_miss(&icache, b->vaddr)) {
            icache_misses++;
        }
    }
    last_block_end = b->end;
}

static void on_load(unsigned int vcpu_index, qemu_plugin_meminfo_t info, uint64_t vaddr, void *userdata)
{
    (void)vcpu_index;
    (void)info;
    (void)userdata;
    if (vaddr < FLASH_END && cache_miss(&dcache, vaddr)) {
        dcache_misses++;
    }
}

static bool starts_with(const char *s, const char *prefix)
{
    return strncmp(s, prefix, strlen(prefix)) == 0;
}

/* True when `m` is one of the NULL-terminated `names`, with an optional S (flags) suffix. */
static bool one_of(const char *m, const char *const *names)
{
    for (; *names != NULL; names++) {
        size_t n = strlen(*names);
        if (strncmp(m, *names, n) == 0 && (m[n] == '\0' || (m[n] == 's' && m[n + 1] == '\0'))) {
            return true;
        }
    }
    return false;
}

static const char *const CONDITIONS[] = {"eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs",
                                         "vc", "hi", "ls", "ge", "lt", "gt", "le", "al", NULL};

static const char *const ALU[] = {"mov", "mvn", "movw", "movt", "add", "addw", "adc", "sub", "subw", "sbc", "rsb",
                                  "and", "orr", "orn", "eor", "bic", "tst", "teq", "cmp", "cmn", "lsl", "lsr",
                                  "asr", "ror", "rrx", "clz", "rbit", "rev", "rev16", "revsh", "sxtb", "sxth",
                                  "uxtb", "uxth", "sxtab", "sxtah", "uxtab", "uxtah", "ubfx", "sbfx", "bfi",
                                  "bfc", "adr", "ssat", "usat", "nop", "qadd", "qsub", "qadd8", "uqadd8",
                                  "uqsub8", "uadd8", "usub8", "sel", "neg", NULL};
static const char *const MUL[] = {"mul", "mla", "mls", "smull", "umull", "smlal", "umlal", "smulbb", "smulbt",
                                  "smultb", "smultt", "smlabb", "smmul", "smmla", NULL};
static const char *const DIV[] = {"sdiv", "udiv", NULL};
static const char *const LOAD[] = {"ldr", "ldrb", "ldrh", "ldrsb", "ldrsh", "ldrex", "ldrexb", "ldrexh", "ldrt", NULL};
static const char *const STORE[] = {"str", "strb", "strh", "strex", "strexb", "strexh", "strt", NULL};
static const char *const PAIR[] = {"ldrd", "strd", NULL};
static const char *const MULTI[] = {"ldm", "ldmia", "ldmdb", "stm", "stmia", "stmdb", "push", "pop", NULL};
static const char *const BRANCH[] = {"b", "bl", "blx", "bx", "cbz", "cbnz", NULL};
static const char *const TABLE[] = {"tbb", "tbh", NULL};
static const char *const BARRIER[] = {"dmb", "dsb", "isb", NULL};
static const char *const SYSTEM[] = {"mrs", "msr", "cpsie", "cpsid", "wfi", "wfe", "sev", "bkpt", "svc", NULL};
static const char *const FP[] = {"vadd", "vsub", "vmul", "vnmul", "vabs", "vneg", "vcmp", "vcmpe", "vcvt", "vcvtr",
                                 "vmov", "vmrs", "vmsr", NULL};
static const char *const FP_MAC[] = {"vmla", "vmls", "vnmla", "vnmls", "vfma", "vfms", "vfnma", "vfnms", NULL};
static const char *const FP_DIVSQRT[] = {"vdiv", "vsqrt", NULL};
static const char *const FP_MULTI[] = {"vldm", "vldmia", "vldmdb", "vstm", "vstmia", "vstmdb", "vpush", "vpop", NULL};

/* The kind of the mnemonic `m` (no width or type suffix), or -1. */
static int kind_of(const char *m)
{
    if (one_of(m, ALU)) return K_ALU;
    if (one_of(m, MUL)) return K_MUL;
    if (one_of(m, DIV)) return K_DIV;
    if (one_of(m, LOAD)) return K_LOAD;
    if (one_of(m, STORE)) return K_STORE;
    if (one_of(m, PAIR)) return K_PAIR;
    if (one_of(m, MULTI)) return K_MULTI;
    if (one_of(m, BRANCH)) return K_BRANCH;
    if (one_of(m, TABLE)) return K_TABLE;
    if (one_of(m, BARRIER)) return K_BARRIER;
    if (one_of(m, SYSTEM)) return K_SYSTEM;
    if (one_of(m, FP)) return K_FP;
    if (one_of(m, FP_MAC)) return K_FP_MAC;
    if (one_of(m, FP_DIVSQRT)) return K_FP_DIVSQRT;
    if (strcmp(m, "vldr") == 0) return K_FP_LOAD;
    if (strcmp(m, "vstr") == 0) return K_FP_STORE;
    if (one_of(m, FP_MULTI)) return K_FP_MULTI;
    if (starts_with(m, "it") && strspn(m + 2, "te") == strlen(m + 2)) return K_IT;
    return -1;
}

/* The kind of a disassembled instruction, and the words a multiple transfer moves. */
static int classify(const char *disas, uint64_t *words)
{
    char m[16];
    size_t n = strcspn(disas, " \t");
    int kind;
    if (n >= sizeof m) {
        n = sizeof m - 1;
    }
    for (size_t i = 0; i < n; i++) {
        m[i] = (char)tolower((unsigned char)disas[i]);
    }
    m[n] = '\0';
    /* Width (.w, .n) and data type (.f32, .s32.f32, ...) suffixes say nothing about the time. */
    char *dot = strchr(m, '.');
    if (dot != NULL) {
        *dot = '\0';
    }
    kind = kind_of(m);
    size_t len = strlen(m);
    if (kind < 0 && len > 2) {
        /* A condition code after the mnemonic: in an IT block, or a conditional branch. */
        for (const char *const *c = CONDITIONS; *c != NULL; c++) {
            if (strcmp(m + len - 2, *c) == 0) {
                char base[16];
                memcpy(base, m, len - 2);
                base[len - 2] = '\0';
                kind = kind_of(base);
                break;
            }
        }
    }
    *words = 0;
    if (kind == K_MULTI || kind == K_FP_MULTI) {
        const char *list = strchr(disas, '{');
        uint64_t regs = 0;
        if (list != NULL) {
            regs = 1;
            for (const char *p = list; *p != '\0' && *p != '}'; p++) {
                regs += *p == ',';
            }
            /* A double register moves two words. */
            if (strchr(list, 'd') != NULL && kind == K_FP_MULTI) {
                regs *= 2;
            }
        }
        *words = regs;
    }
    if (kind < 0) {
        bool known = false;
        for (int i = 0; i < unknown_n; i++) {
            known |= strcmp(unknown[i], m) == 0;
        }
        if (!known && unknown_n < 16) {
            strcpy(unknown[unknown_n++], m);
        }
        kind = K_OTHER;
    }
    return kind;
}

/* True for a single load that the next load or store can pipeline with (TRM 3.3.2). */
static bool single_load(int kind)
{
    return kind == K_LOAD || kind == K_LOAD_PIPE;
}

static bool loads(int kind)
{
    return kind == K_LOAD || kind == K_LOAD_PIPE || kind == K_LOAD_PC || kind == K_PAIR || kind == K_MULTI ||
           kind == K_FP_LOAD || kind == K_FP_MULTI;
}

/* True when the address in `ops` is a base register plus a register: `[r1, r2]`, `[r1, r2, lsl #1]`. */
static bool register_offset(const char *ops)
{
    const char *open = strchr(ops, '[');
    const char *comma = open != NULL ? strchr(open, ',') : NULL;
    const char *close = open != NULL ? strchr(open, ']') : NULL;
    if (comma == NULL || close == NULL || comma > close) {
        return false;
    }
    comma++;
    comma += strspn(comma, " ");
    return *comma != '#';
}

/* The operands of a disassembled instruction, after its mnemonic. */
static const char *operands(const char *disas)
{
    const char *p = disas + strcspn(disas, " \t");
    return p + strspn(p, " \t");
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    size_t n = qemu_plugin_tb_n_insns(tb);
    int before = -1;
    size_t before_size = 0;
    struct block *b = calloc(1, sizeof *b);
    (void)id;
    if (b == NULL) {
        return;
    }
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        char *disas = qemu_plugin_insn_disas(insn);
        uint64_t words = 0;
        const char *text = disas != NULL ? disas : "";
        int kind = classify(text, &words);
        const char *ops = operands(text);
        if (kind == K_LOAD && starts_with(ops, "pc")) {
            kind = K_LOAD_PC;
        } else if (kind == K_LOAD && before >= 0 && single_load(before)) {
            kind = K_LOAD_PIPE;
        } else if (kind == K_STORE && register_offset(ops)) {
            kind = K_STORE_REG;
        }
        if (kind == K_IT && before >= 0 && before_size == 2) kind = K_IT_FOLDED;
        free(disas);
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &insn_count, 1);
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &kind_count[kind], 1);
        if (words > 0) {
            qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &multi_words, words);
        }
        if (loads(kind)) {
            qemu_plugin_register_vcpu_mem_cb(insn, on_load, QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_MEM_R, NULL);
        }
        if (qemu_plugin_insn_vaddr(insn) == mark_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_mark, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
        before = kind;
        before_size = qemu_plugin_insn_size(insn);
        if (i + 1 == n) {
            b->end = qemu_plugin_insn_vaddr(insn) + before_size;
        }
    }
    /* A block translated again (after a flush) gets a second record; the runner adds them. */
    b->vaddr = qemu_plugin_tb_vaddr(tb);
    b->n_insns = n;
    b->next = blocks;
    blocks = b;
    qemu_plugin_register_vcpu_tb_exec_cb(tb, on_block, QEMU_PLUGIN_CB_NO_REGS, b);
    if (profile) {
        qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &b->executions, 1);
    }
}

static void on_plugin_exit(qemu_plugin_id_t id, void *userdata)
{
    char line[96];
    (void)id;
    (void)userdata;
    for (struct block *b = blocks; b != NULL; b = b->next) {
        if (b->executions > 0) {
            snprintf(line, sizeof line, "block 0x%" PRIx64 " %" PRIu64 " %" PRIu64 "\n", b->vaddr, b->n_insns,
                     b->executions);
            qemu_plugin_outs(line);
        }
    }
    for (int i = 0; i < unknown_n; i++) {
        snprintf(line, sizeof line, "unknown %.15s\n", unknown[i]);
        qemu_plugin_outs(line);
    }
    snprintf(line, sizeof line, "total %" PRIu64 "\n", insn_count);
    qemu_plugin_outs(line);
}

__attribute__((visibility("default"))) int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info,
                                                              int argc, char **argv)
{
    char line[512];
    int len;
    (void)info;
    for (int i = 0; i < argc; i++) {
        if (strncmp(argv[i], "mark=", 5) == 0) {
            mark_addr = strtoull(argv[i] + 5, NULL, 0);
        } else if (strcmp(argv[i], "profile=on") == 0) {
            profile = true;
        } else {
            fprintf(stderr, "insn_count: unknown argument %s\n", argv[i]);
            return -1;
        }
    }
    len = snprintf(line, sizeof line, "kinds");
    for (int k = 0; k < KINDS; k++) {
        len += snprintf(line + len, sizeof line - len, " %s", KIND_NAMES[k]);
    }
    snprintf(line + len, sizeof line - len, "\n");
    qemu_plugin_outs(line);
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    qemu_plugin_register_atexit_cb(id, on_plugin_exit, NULL);
    return 0;
}
