/* Host test program of sw/mstrack_drv.c (tests/test_sw_driver.py builds and drives it).
 *
 * Reads commands on stdin, one per line, and prints one line per command:
 *   word H0 H1 H2 H3 H4      decode a result word v1 (hex, 32 bits each, LSB first)
 *   word2 H0 H1 H2 H3 H4     decode a result word v2
 *   regs OFF=VAL ...         set registers of a fake register file (hex byte offset = hex value)
 *   read                     mstrack_read_result on the fake register file
 *   read2                    mstrack_read_result_v2 on the fake register file
 *   irq                      mstrack_irq_handler; prints the returned bits, INT_STATUS written, the result
 *   irq2                     the same, then dev.last_v2 (core v2)
 *   init W H                 mstrack_init; prints the return code, result_version, FRAME_SIZE, CTRL, CMD, INT_STATUS
 *   start X Y W H MASK       mstrack_start; prints the return code, INIT_POS, INIT_SIZE, CMD, INT_ENABLE, CTRL
 *   slots N                  dev.max_targets = N (what mstrack_init reads from MULTI)
 *   add X Y W H              mstrack_add; prints the return code, the id, INIT_POS, INIT_SIZE, CMD
 *   remove ID                mstrack_remove; prints the return code, TARGET, CMD
 *   frame                    mstrack_read_frame; prints the return code, target_mask, RES_SEL, and per id of
 *                            the mask t<id>=cx and i<id>=target_id
 *   irqm                     mstrack_irq_handler (multi-target); prints the bits, target_mask, box_rejected
 * Results print as name=value (decimal) in the field order of the structs.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mstrack_drv.h"

static uint32_t mem[1024];                   /* 4 KiB fake register file */

static void print_result(const mstrack_result_t *r)
{
    printf("valid=%lu frame_count=%lu flags=%lu err_code=%lu cx=%lu cy=%lu rho_c=%lu rho_e=%lu "
           "alpha_c=%lu iter_c=%lu iter_e=%lu stop_c=%lu stop_e=%lu box_w=%lu box_h=%lu\n",
           (unsigned long)r->valid, (unsigned long)r->frame_count, (unsigned long)r->flags,
           (unsigned long)r->err_code, (unsigned long)r->cx, (unsigned long)r->cy,
           (unsigned long)r->rho_c, (unsigned long)r->rho_e, (unsigned long)r->alpha_c,
           (unsigned long)r->iter_c, (unsigned long)r->iter_e, (unsigned long)r->stop_c,
           (unsigned long)r->stop_e, (unsigned long)r->box_w, (unsigned long)r->box_h);
}

static void print_v2(const mstrack_result_v2_t *r)
{
    printf("cx=%lu cy=%lu w8=%lu h8=%lu rho=%lu confidence=%lu status=%lu iter=%lu stop=%lu "
           "decim_log2=%lu searched=%lu flags=%lu err_code=%lu frame_count=%lu valid=%lu\n",
           (unsigned long)r->cx, (unsigned long)r->cy, (unsigned long)r->w8, (unsigned long)r->h8,
           (unsigned long)r->rho, (unsigned long)r->confidence, (unsigned long)r->status,
           (unsigned long)r->iter, (unsigned long)r->stop, (unsigned long)r->decim_log2,
           (unsigned long)r->searched, (unsigned long)r->flags, (unsigned long)r->err_code,
           (unsigned long)r->frame_count, (unsigned long)r->valid);
}

#define AT(NAME) mem[offsetof(ms_tracker_regs_t, NAME) / 4u]

int main(void)
{
    char line[4096];
    mstrack_dev_t dev;
    memset(&dev, 0, sizeof dev);
    dev.base = (uintptr_t)mem;
    dev.irq_mask = 0;
    dev.irq_count = 0;
    dev.result_version = 1;
    while (fgets(line, sizeof line, stdin) != NULL) {
        char *tok = strtok(line, " \t\r\n");
        if (tok == NULL) {
            continue;
        }
        if (strcmp(tok, "word") == 0 || strcmp(tok, "word2") == 0) {
            uint32_t w[5] = {0, 0, 0, 0, 0};
            int v2 = strcmp(tok, "word2") == 0;
            unsigned i;
            for (i = 0; i < 5u; i++) {
                char *t = strtok(NULL, " \t\r\n");
                w[i] = t ? (uint32_t)strtoul(t, NULL, 16) : 0u;
            }
            if (v2) {
                mstrack_result_v2_t r;
                mstrack_decode_word_v2(w, &r);
                print_v2(&r);
            } else {
                mstrack_result_t r;
                mstrack_decode_word(w, &r);
                print_result(&r);
            }
        } else if (strcmp(tok, "regs") == 0) {
            char *t;
            while ((t = strtok(NULL, " \t\r\n")) != NULL) {
                char *eq = strchr(t, '=');
                unsigned long off = strtoul(t, NULL, 16);
                if (eq != NULL && off < sizeof mem) {
                    mem[off / 4u] = (uint32_t)strtoul(eq + 1, NULL, 16);
                }
            }
            printf("ok\n");
        } else if (strcmp(tok, "read") == 0) {
            mstrack_result_t r;
            int rc = mstrack_read_result(&dev, &r);
            printf("rc=%d ", rc);
            print_result(&r);
        } else if (strcmp(tok, "read2") == 0) {
            mstrack_result_v2_t r;
            int rc = mstrack_read_result_v2(&dev, &r);
            printf("rc=%d ", rc);
            print_v2(&r);
        } else if (strcmp(tok, "irq2") == 0) {
            mstrack_result_t r;
            uint32_t st;
            memset(&r, 0, sizeof r);
            memset(&dev.last_v2, 0, sizeof dev.last_v2);
            st = mstrack_irq_handler(&dev, &r);
            printf("st=%lu written=%lu rho_c=%lu box_w=%lu ", (unsigned long)st, (unsigned long)AT(INT_STATUS),
                   (unsigned long)r.rho_c, (unsigned long)r.box_w);
            print_v2(&dev.last_v2);
        } else if (strcmp(tok, "irq") == 0) {
            mstrack_result_t r;
            uint32_t st;
            memset(&r, 0, sizeof r);
            st = mstrack_irq_handler(&dev, &r);
            printf("st=%lu written=%lu ", (unsigned long)st, (unsigned long)AT(INT_STATUS));
            print_result(&r);
        } else if (strcmp(tok, "init") == 0) {
            char *a = strtok(NULL, " \t\r\n");
            char *b = strtok(NULL, " \t\r\n");
            int rc = mstrack_init(&dev, (uintptr_t)mem, a ? (uint32_t)strtoul(a, NULL, 10) : 0u,
                                  b ? (uint32_t)strtoul(b, NULL, 10) : 0u);
            printf("rc=%d RV=%lu FRAME_SIZE=%lu CTRL=%lu CMD=%lu INT_STATUS=%lu\n", rc,
                   (unsigned long)dev.result_version, (unsigned long)AT(FRAME_SIZE),
                   (unsigned long)AT(CTRL), (unsigned long)AT(CMD), (unsigned long)AT(INT_STATUS));
        } else if (strcmp(tok, "start") == 0) {
            long v[5] = {0, 0, 0, 0, 0};
            unsigned i;
            int rc;
            for (i = 0; i < 5u; i++) {
                char *t = strtok(NULL, " \t\r\n");
                v[i] = t ? strtol(t, NULL, 10) : 0;
            }
            rc = mstrack_start(&dev, (int32_t)v[0], (int32_t)v[1], (uint32_t)v[2], (uint32_t)v[3], (uint32_t)v[4]);
            printf("rc=%d INIT_POS=%lu INIT_SIZE=%lu CMD=%lu INT_ENABLE=%lu CTRL=%lu\n", rc,
                   (unsigned long)AT(INIT_POS), (unsigned long)AT(INIT_SIZE), (unsigned long)AT(CMD),
                   (unsigned long)AT(INT_ENABLE), (unsigned long)AT(CTRL));
        } else if (strcmp(tok, "slots") == 0) {
            char *a = strtok(NULL, " \t\r\n");
            dev.max_targets = a ? (uint32_t)strtoul(a, NULL, 10) : 0u;
            printf("ok\n");
        } else if (strcmp(tok, "add") == 0) {
            long v[4] = {0, 0, 0, 0};
            unsigned i;
            uint32_t id = 99u;
            int rc;
            for (i = 0; i < 4u; i++) {
                char *t = strtok(NULL, " \t\r\n");
                v[i] = t ? strtol(t, NULL, 10) : 0;
            }
            rc = mstrack_add(&dev, (int32_t)v[0], (int32_t)v[1], (uint32_t)v[2], (uint32_t)v[3], &id);
            printf("rc=%d id=%lu INIT_POS=%lu INIT_SIZE=%lu CMD=%lu\n", rc, (unsigned long)id,
                   (unsigned long)AT(INIT_POS), (unsigned long)AT(INIT_SIZE), (unsigned long)AT(CMD));
        } else if (strcmp(tok, "remove") == 0) {
            char *a = strtok(NULL, " \t\r\n");
            int rc = mstrack_remove(&dev, a ? (uint32_t)strtoul(a, NULL, 10) : 0u);
            printf("rc=%d TARGET=%lu CMD=%lu\n", rc, (unsigned long)AT(TARGET), (unsigned long)AT(CMD));
        } else if (strcmp(tok, "frame") == 0) {
            unsigned id;
            int rc = mstrack_read_frame(&dev);
            printf("rc=%d mask=%lu RES_SEL=%lu", rc, (unsigned long)dev.target_mask, (unsigned long)AT(RES_SEL));
            for (id = 0; id < MSTRACK_MAX_TARGETS; id++) {
                if (dev.target_mask & (1u << id)) {
                    printf(" t%u=%lu i%u=%lu", id, (unsigned long)dev.target[id].cx, id,
                           (unsigned long)dev.target[id].target_id);
                }
            }
            printf("\n");
        } else if (strcmp(tok, "irqm") == 0) {
            uint32_t st = mstrack_irq_handler(&dev, NULL);
            printf("st=%lu mask=%lu box_rejected=%lu\n", (unsigned long)st, (unsigned long)dev.target_mask,
                   (unsigned long)dev.box_rejected);
        } else {
            printf("unknown command %s\n", tok);
        }
        fflush(stdout);
    }
    return 0;
}
