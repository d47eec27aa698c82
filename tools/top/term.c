/* term.c — see term.h. Plain termios and ANSI escapes (no curses): they
 * work over ssh in any terminal emulator that shows an 80x24 screen. */
#include "term.h"

#include <signal.h>
#include <string.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

/* One terminal per process: the saved state must be reachable from signal
 * handlers, which take no arguments. */
static struct termios term_saved;
static volatile sig_atomic_t term_active;

/* alternate screen on, cursor hidden, cleared */
#define TERM_ENTER_SEQ "\033[?1049h\033[?25l\033[H\033[2J"
/* attributes reset, cursor shown, alternate screen off */
#define TERM_LEAVE_SEQ "\033[0m\033[?25h\033[?1049l"

static void term_fatal(int sig)
{
	term_leave();
	signal(sig, SIG_DFL);
	raise(sig);
}

int term_enter(void)
{
	if (!isatty(STDIN_FILENO) || !isatty(STDOUT_FILENO) || tcgetattr(STDIN_FILENO, &term_saved) != 0)
		return -1;
	struct termios raw = term_saved;
	/* ICANON: keys arrive one by one, not per line; ECHO: keys not printed;
	 * ISIG: Ctrl-C arrives as byte 3 and quits through the same path as q
	 * (SIGINT from elsewhere is still handled); IEXTEN: no Ctrl-V quoting. */
	raw.c_lflag &= ~(tcflag_t)(ICANON | ECHO | ISIG | IEXTEN);
	/* IXON: Ctrl-S/Ctrl-Q are keys, not flow control; ICRNL: Enter is CR. */
	raw.c_iflag &= ~(tcflag_t)(IXON | ICRNL);
	/* OPOST stays on: the screen is written with explicit CR LF anyway. */
	raw.c_cc[VMIN] = 0; /* reads never block: stdin is polled */
	raw.c_cc[VTIME] = 0;
	if (tcsetattr(STDIN_FILENO, TCSAFLUSH, &raw) != 0)
		return -1;
	term_active = 1;
	int fatal[] = { SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT };
	for (size_t i = 0; i < sizeof(fatal) / sizeof(fatal[0]); i++)
		signal(fatal[i], term_fatal);
	ssize_t w = write(STDOUT_FILENO, TERM_ENTER_SEQ, sizeof(TERM_ENTER_SEQ) - 1);
	(void)w;
	return 0;
}

void term_leave(void)
{
	if (!term_active)
		return;
	term_active = 0;
	/* tcsetattr and write are async-signal-safe */
	tcsetattr(STDIN_FILENO, TCSAFLUSH, &term_saved);
	ssize_t w = write(STDOUT_FILENO, TERM_LEAVE_SEQ, sizeof(TERM_LEAVE_SEQ) - 1);
	(void)w;
}

void term_size(int *rows, int *cols)
{
	struct winsize ws;
	*rows = 24;
	*cols = 80;
	if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_row > 0 && ws.ws_col > 0) {
		*rows = ws.ws_row;
		*cols = ws.ws_col;
	}
}
