/* mstrack_drv: bare-metal driver of the mstrack tracking core (see mstrack_drv.h). */
#include "mstrack_drv.h"

/* one aligned 32-bit access at the offset of a register of the generated map: a volatile load or
 * store, or with MSTRACK_IO_EXTERN the platform's mstrack_io_read32 / mstrack_io_write32 */
#define ADDR(dev, NAME) ((dev)->base + offsetof(ms_tracker_regs_t, NAME))
#ifdef MSTRACK_IO_EXTERN
#define RD(dev, NAME) mstrack_io_read32(ADDR(dev, NAME))
#define WR(dev, NAME, v) mstrack_io_write32(ADDR(dev, NAME), (v))
#else
#define RD(dev, NAME) (*(volatile uint32_t *)ADDR(dev, NAME))
#define WR(dev, NAME, v) (*(volatile uint32_t *)ADDR(dev, NAME) = (v))
#endif
/* field of a register value, with the generated mask / position */
#define FIELD(v, REGNAME, FNAME) \
    (((v) & MS_TRACKER_REGS__##REGNAME##__##FNAME##_bm) >> MS_TRACKER_REGS__##REGNAME##__##FNAME##_bp)
#define PUT(REGNAME, FNAME, x) \
    ((((uint32_t)(x)) << MS_TRACKER_REGS__##REGNAME##__##FNAME##_bp) & MS_TRACKER_REGS__##REGNAME##__##FNAME##_bm)

/* bits off .. off + w - 1 (w <= 32) of a word held LSB first in 32-bit pieces */
static uint32_t bits(const uint32_t *words, unsigned off, unsigned w)
{
    unsigned i = off / 32u, s = off % 32u;
    uint64_t v = words[i] >> s;
    if (s + w > 32u) {
        v |= (uint64_t)words[i + 1u] << (32u - s);
    }
    return (uint32_t)(v & ((w >= 32u) ? 0xFFFFFFFFu : ((1u << w) - 1u)));
}

int mstrack_init(mstrack_dev_t *dev, uintptr_t base, uint32_t width, uint32_t height)
{
    uint32_t v;
    dev->base = base;
    dev->irq_mask = 0;
    dev->irq_count = 0;
    dev->result_version = 0;
    dev->last.valid = 0;
    dev->last_v2.valid = 0;
    dev->max_targets = 0;
    dev->target_mask = 0;
    dev->box_rejected = 0;
    dev->add_refused = 0;
    dev->shared_engine = 0;
    if (RD(dev, ID) != MSTRACK_MAGIC) {
        return MSTRACK_ERR_ID;
    }
    v = RD(dev, VERSION);
    if (FIELD(v, VERSION, MAP_MAJOR) != MSTRACK_MAP_MAJOR || FIELD(v, VERSION, RESULT_VERSION) < 1u ||
        FIELD(v, VERSION, RESULT_VERSION) > 2u) {
        return MSTRACK_ERR_VERSION;
    }
    dev->result_version = FIELD(v, VERSION, RESULT_VERSION);
    if (FIELD(v, VERSION, MAP_MINOR) >= 3u) {
        uint32_t m = RD(dev, MULTI);
        dev->max_targets = FIELD(m, MULTI, MAX_TARGETS);
        dev->shared_engine = FIELD(m, MULTI, SHARED_ENGINE);   /* 0 before map minor 4 */
    }
    if (width < 3u || height < 3u || width > FIELD(RD(dev, FORMAT), FORMAT, MAX_FRAME_W) || height > 0xFFFFu) {
        return MSTRACK_ERR_ARG;
    }
    WR(dev, CTRL, 0);                                      /* frames dropped from the next start */
    WR(dev, INT_ENABLE, 0);
    WR(dev, INT_STATUS, MSTRACK_IRQ_ALL);                  /* W1C */
    WR(dev, CMD, PUT(CMD, CLEAR_COUNTERS, 1u));
    WR(dev, FRAME_SIZE, PUT(FRAME_SIZE, WIDTH, width) | PUT(FRAME_SIZE, HEIGHT, height));
    return MSTRACK_OK;
}

int mstrack_start(mstrack_dev_t *dev, int32_t x, int32_t y, uint32_t w, uint32_t h, uint32_t irq_mask)
{
    if (x < -32768 || x > 32767 || y < -32768 || y > 32767 || w > 0xFFFFu || h > 0xFFFFu) {
        return MSTRACK_ERR_ARG;
    }
    WR(dev, INIT_POS, PUT(INIT_POS, X, (uint32_t)x & 0xFFFFu) | PUT(INIT_POS, Y, (uint32_t)y & 0xFFFFu));
    WR(dev, INIT_SIZE, PUT(INIT_SIZE, WIDTH, w) | PUT(INIT_SIZE, HEIGHT, h));
    WR(dev, CMD, PUT(CMD, INIT, 1u));                      /* box copied now, taken between frames */
    mstrack_enable(dev, irq_mask);
    return MSTRACK_OK;
}

void mstrack_enable(mstrack_dev_t *dev, uint32_t irq_mask)
{
    dev->irq_mask = irq_mask & MSTRACK_IRQ_ALL;
    WR(dev, INT_ENABLE, dev->irq_mask);
    WR(dev, CTRL, PUT(CTRL, ENABLE, 1u));
}

/* wait for the report of the command just written: CMD_STATUS.pending falls */
static int wait_command(const mstrack_dev_t *dev, uint32_t *code, uint32_t *id)
{
    uint32_t n, v;
    for (n = 0; n < MSTRACK_CMD_POLLS; ++n) {
        v = RD(dev, CMD_STATUS);
        if (!FIELD(v, CMD_STATUS, PENDING)) {
            *code = FIELD(v, CMD_STATUS, CODE);
            *id = FIELD(v, CMD_STATUS, ID);
            return MSTRACK_OK;
        }
    }
    return MSTRACK_ERR_TIMEOUT;
}

int mstrack_add(mstrack_dev_t *dev, int32_t x, int32_t y, uint32_t w, uint32_t h, uint32_t *id)
{
    uint32_t code = 0u, slot = 0u;
    int rc;
    if (dev->max_targets == 0u) {
        return MSTRACK_ERR_SINGLE;
    }
    if (x < -32768 || x > 32767 || y < -32768 || y > 32767 || w > 0xFFFFu || h > 0xFFFFu) {
        return MSTRACK_ERR_ARG;
    }
    WR(dev, INIT_POS, PUT(INIT_POS, X, (uint32_t)x & 0xFFFFu) | PUT(INIT_POS, Y, (uint32_t)y & 0xFFFFu));
    WR(dev, INIT_SIZE, PUT(INIT_SIZE, WIDTH, w) | PUT(INIT_SIZE, HEIGHT, h));
    WR(dev, CMD, PUT(CMD, ADD, 1u));
    rc = wait_command(dev, &code, &slot);
    if (rc != MSTRACK_OK) {
        return rc;
    }
    if (code != 0u) {
        return MSTRACK_ERR_FULL;
    }
    dev->box_rejected &= ~(1u << slot);
    dev->add_refused &= ~(1u << slot);
    if (id != NULL) {
        *id = slot;
    }
    return MSTRACK_OK;
}

int mstrack_remove(mstrack_dev_t *dev, uint32_t id)
{
    uint32_t code = 0u, slot = 0u;
    int rc;
    if (dev->max_targets == 0u) {
        return MSTRACK_ERR_SINGLE;
    }
    if (id >= dev->max_targets) {
        return MSTRACK_ERR_ARG;
    }
    WR(dev, TARGET, PUT(TARGET, ID, id));
    WR(dev, CMD, PUT(CMD, REMOVE, 1u));
    rc = wait_command(dev, &code, &slot);
    if (rc != MSTRACK_OK) {
        return rc;
    }
    return code == 0u ? MSTRACK_OK : MSTRACK_ERR_ARG;
}

uint32_t mstrack_live(const mstrack_dev_t *dev)
{
    return FIELD(RD(dev, MULTI), MULTI, LIVE);
}

void mstrack_stop(mstrack_dev_t *dev)
{
    WR(dev, CTRL, 0);
    WR(dev, INT_ENABLE, 0);
    dev->irq_mask = 0;
}

/* RES_HEAD first (its read takes the snapshot of one whole result), then the centre: the fields
 * both result words have; the macro fills them in either result struct. */
#define READ_HEAD(dev, r, v)                                  \
    do {                                                      \
        (v) = RD(dev, RES_HEAD);                              \
        (r)->valid = FIELD(v, RES_HEAD, VALID);               \
        (r)->frame_count = FIELD(v, RES_HEAD, FRAME_COUNT);   \
        (r)->flags = FIELD(v, RES_HEAD, FLAGS);               \
        (r)->err_code = FIELD(v, RES_HEAD, ERR_CODE);         \
        (r)->cx = RD(dev, RES_CX);                            \
        (r)->cy = RD(dev, RES_CY);                            \
    } while (0)

int mstrack_read_result(const mstrack_dev_t *dev, mstrack_result_t *r)
{
    uint32_t v;
    READ_HEAD(dev, r, v);
    r->rho_c = RD(dev, RES_RHO_C);
    r->rho_e = RD(dev, RES_RHO_E);
    r->alpha_c = RD(dev, RES_ALPHA);
    v = RD(dev, RES_ITER);
    r->iter_c = FIELD(v, RES_ITER, ITER_C);
    r->iter_e = FIELD(v, RES_ITER, ITER_E);
    r->stop_c = FIELD(v, RES_ITER, STOP_C);
    r->stop_e = FIELD(v, RES_ITER, STOP_E);
    v = RD(dev, RES_BOX);
    r->box_w = FIELD(v, RES_BOX, BOX_W);
    r->box_h = FIELD(v, RES_BOX, BOX_H);
    return r->valid ? MSTRACK_OK : MSTRACK_NO_RESULT;
}

int mstrack_read_result_v2(const mstrack_dev_t *dev, mstrack_result_v2_t *r)
{
    uint32_t v;
    READ_HEAD(dev, r, v);
    r->target_id = FIELD(v, RES_HEAD, TARGET_ID);
    r->rho = RD(dev, RES_RHO_C);
    r->w8 = RD(dev, RES_W8);
    r->h8 = RD(dev, RES_H8);
    r->confidence = RD(dev, RES_CONF);
    v = RD(dev, RES_STATE);
    r->status = FIELD(v, RES_STATE, STATUS);
    r->iter = FIELD(v, RES_STATE, ITER);
    r->stop = FIELD(v, RES_STATE, STOP);
    r->decim_log2 = FIELD(v, RES_STATE, DECIM_LOG2);
    r->searched = FIELD(v, RES_STATE, SEARCHED);
    return r->valid ? MSTRACK_OK : MSTRACK_NO_RESULT;
}

int mstrack_read_target(const mstrack_dev_t *dev, uint32_t id, mstrack_result_v2_t *r)
{
    WR(dev, RES_SEL, PUT(RES_SEL, ID, id));
    return mstrack_read_result_v2(dev, r);
}

int mstrack_read_frame(mstrack_dev_t *dev)
{
    unsigned tries, id;
    uint32_t v, mask, fc;
    int torn;
    if (dev->max_targets == 0u) {
        return MSTRACK_ERR_SINGLE;
    }
    for (tries = 0; tries < 3u; ++tries) {
        v = RD(dev, RES_MASK);
        mask = FIELD(v, RES_MASK, MASK);
        fc = FIELD(v, RES_MASK, FRAME_COUNT);
        torn = 0;
        for (id = 0; id < MSTRACK_MAX_TARGETS && !torn; ++id) {
            if (mask & (1u << id)) {
                (void)mstrack_read_target(dev, id, &dev->target[id]);
                torn = dev->target[id].frame_count != fc;
            }
        }
        if (!torn && FIELD(RD(dev, RES_MASK), RES_MASK, FRAME_COUNT) == fc) {
            dev->target_mask = mask;
            return MSTRACK_OK;
        }
    }
    dev->target_mask = 0u;
    return MSTRACK_ERR_TORN;
}

void mstrack_read_raw(const mstrack_dev_t *dev, uint32_t words[5])
{
    words[0] = RD(dev, RES_RAW0);
    words[1] = RD(dev, RES_RAW1);
    words[2] = RD(dev, RES_RAW2);
    words[3] = RD(dev, RES_RAW3);
    words[4] = RD(dev, RES_RAW4);
}

void mstrack_decode_word(const uint32_t *words, mstrack_result_t *r)
{
    r->valid = 1u;
    r->cx = bits(words, MSTRACK_RES_CX_OFF, MSTRACK_RES_CX_W);
    r->cy = bits(words, MSTRACK_RES_CY_OFF, MSTRACK_RES_CY_W);
    r->rho_c = bits(words, MSTRACK_RES_RHO_C_OFF, MSTRACK_RES_RHO_C_W);
    r->rho_e = bits(words, MSTRACK_RES_RHO_E_OFF, MSTRACK_RES_RHO_E_W);
    r->alpha_c = bits(words, MSTRACK_RES_ALPHA_C_OFF, MSTRACK_RES_ALPHA_C_W);
    r->iter_c = bits(words, MSTRACK_RES_ITER_C_OFF, MSTRACK_RES_ITER_C_W);
    r->iter_e = bits(words, MSTRACK_RES_ITER_E_OFF, MSTRACK_RES_ITER_E_W);
    r->stop_c = bits(words, MSTRACK_RES_STOP_C_OFF, MSTRACK_RES_STOP_C_W);
    r->stop_e = bits(words, MSTRACK_RES_STOP_E_OFF, MSTRACK_RES_STOP_E_W);
    r->flags = bits(words, MSTRACK_RES_FLAGS_OFF, MSTRACK_RES_FLAGS_W);
    r->err_code = bits(words, MSTRACK_RES_ERR_CODE_OFF, MSTRACK_RES_ERR_CODE_W);
    r->box_w = bits(words, MSTRACK_RES_BOX_W_OFF, MSTRACK_RES_BOX_W_W);
    r->box_h = bits(words, MSTRACK_RES_BOX_H_OFF, MSTRACK_RES_BOX_H_W);
    r->frame_count = bits(words, MSTRACK_RES_FRAME_COUNT_OFF, MSTRACK_RES_FRAME_COUNT_W);
}

void mstrack_decode_word_v2(const uint32_t *words, mstrack_result_v2_t *r)
{
    r->cx = bits(words, MSTRACK_RES2_CX_OFF, MSTRACK_RES2_CX_W);
    r->cy = bits(words, MSTRACK_RES2_CY_OFF, MSTRACK_RES2_CY_W);
    r->w8 = bits(words, MSTRACK_RES2_W8_OFF, MSTRACK_RES2_W8_W);
    r->h8 = bits(words, MSTRACK_RES2_H8_OFF, MSTRACK_RES2_H8_W);
    r->rho = bits(words, MSTRACK_RES2_RHO_OFF, MSTRACK_RES2_RHO_W);
    r->confidence = bits(words, MSTRACK_RES2_CONFIDENCE_OFF, MSTRACK_RES2_CONFIDENCE_W);
    r->status = bits(words, MSTRACK_RES2_STATUS_OFF, MSTRACK_RES2_STATUS_W);
    r->iter = bits(words, MSTRACK_RES2_ITER_OFF, MSTRACK_RES2_ITER_W);
    r->stop = bits(words, MSTRACK_RES2_STOP_OFF, MSTRACK_RES2_STOP_W);
    r->decim_log2 = bits(words, MSTRACK_RES2_DECIM_LOG2_OFF, MSTRACK_RES2_DECIM_LOG2_W);
    r->searched = bits(words, MSTRACK_RES2_SEARCHED_OFF, MSTRACK_RES2_SEARCHED_W);
    r->flags = bits(words, MSTRACK_RES2_FLAGS_OFF, MSTRACK_RES2_FLAGS_W);
    r->err_code = bits(words, MSTRACK_RES2_ERR_CODE_OFF, MSTRACK_RES2_ERR_CODE_W);
    r->frame_count = bits(words, MSTRACK_RES2_FRAME_COUNT_OFF, MSTRACK_RES2_FRAME_COUNT_W);
    r->valid = 1u;
    r->target_id = 0u;
}

uint32_t mstrack_irq_handler(mstrack_dev_t *dev, mstrack_result_t *r)
{
    uint32_t st = RD(dev, INT_STATUS) & MSTRACK_IRQ_ALL;
    if (st == 0u) {
        return 0u;
    }
    dev->irq_count++;
    if (st & MSTRACK_IRQ_COMMAND) {
        uint32_t v = RD(dev, CMD_STATUS);
        if (FIELD(v, CMD_STATUS, CODE) == 3u) {
            dev->box_rejected |= 1u << FIELD(v, CMD_STATUS, ID);
        } else if (FIELD(v, CMD_STATUS, CODE) == 2u) {
            dev->add_refused |= 1u << FIELD(v, CMD_STATUS, ID);
        }
    }
    if ((st & MSTRACK_IRQ_RESULT) && dev->max_targets != 0u) {
        (void)mstrack_read_frame(dev);
    } else if (st & MSTRACK_IRQ_RESULT) {
        if (dev->result_version == 2u) {
            const mstrack_result_v2_t *v2 = &dev->last_v2;
            (void)mstrack_read_result_v2(dev, &dev->last_v2);
            dev->last.valid = v2->valid;
            dev->last.frame_count = v2->frame_count;
            dev->last.flags = v2->flags;
            dev->last.err_code = v2->err_code;
            dev->last.cx = v2->cx;
            dev->last.cy = v2->cy;
            dev->last.rho_c = v2->rho;
            dev->last.rho_e = 0u;
            dev->last.alpha_c = 0u;
            dev->last.iter_c = 0u;
            dev->last.iter_e = 0u;
            dev->last.stop_c = 0u;
            dev->last.stop_e = 0u;
            dev->last.box_w = 0u;
            dev->last.box_h = 0u;
        } else {
            (void)mstrack_read_result(dev, &dev->last);
        }
        if (r != NULL) {
            *r = dev->last;
        }
    }
    WR(dev, INT_STATUS, st);                               /* W1C: exactly the bits handled */
    return st;
}

void mstrack_read_counters(const mstrack_dev_t *dev, mstrack_counters_t *c)
{
    c->results = RD(dev, RESULT_COUNT);
    c->lost = RD(dev, LOST_COUNT);
    c->errors = RD(dev, ERROR_COUNT);
    c->rejected = RD(dev, REJECT_COUNT);
    c->dropped = RD(dev, DROP_COUNT);
}

void mstrack_clear_counters(const mstrack_dev_t *dev)
{
    WR(dev, CMD, PUT(CMD, CLEAR_COUNTERS, 1u));
}
