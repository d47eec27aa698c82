/* term.h — the terminal for undulate-top: raw keys, alternate screen, and
 * restoration on every way out (normal exit, q, Ctrl-C, SIGTERM, SIGHUP, a
 * crash). */
#ifndef UNDULATE_TOP_TERM_H
#define UNDULATE_TOP_TERM_H

#include <stdbool.h>

/* Raw mode on stdin, alternate screen, hidden cursor. Returns 0 or -1 (not a terminal). */
int term_enter(void);
/* Undoes term_enter; safe to call twice and from a signal handler. */
void term_leave(void);
/* Terminal size; 80x24 when unknown. */
void term_size(int *rows, int *cols);

#endif
