/*
 * setup_priv.h — what the files of the start-up and safe stop share:
 * setup.c (every servo family, through its model: servo_model.h's
 * sm_setup) and setup_io.c (the transactions it uses, tried again).
 * Nothing outside them includes this.
 */
#ifndef UNDULATE_DAEMON_SETUP_PRIV_H
#define UNDULATE_DAEMON_SETUP_PRIV_H

#include "setup.h"

/* ---- setup_io.c --------------------------------------------------------------------------- */
/* Before try t of a transaction: wait for a quiet line (setup.h). */
void setup_pause(struct bus *bus, int t, uint8_t id, const char *what, int last);
/* A READ or WRITE tried SETUP_TRIES times, on the bus's protocol (2.0: the
 * 16-bit address; *eb gets the error byte or ERR field). */
int setup_read(struct bus *bus, uint8_t id, uint16_t addr, uint16_t len, uint8_t *out, uint8_t *eb);
int setup_write(struct bus *bus, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply,
                uint8_t *eb);

#endif
