/*
 * simctl.c — send one command line to undulate-sim's control socket and
 * print the answer (the benchmark injects faults with it at a chosen moment).
 * Built by bench/run.sh.
 *
 *   simctl SOCKET 'fault r1 3 no-reply'     exit 0 when the answer starts "ok"
 */
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

/* The sim answers within one loop turn; a second is generous. */
#define SIMCTL_TIMEOUT_MS 1000

int main(int argc, char **argv)
{
	if (argc != 3) {
		fprintf(stderr, "usage: simctl SOCKET COMMAND\n");
		return 2;
	}
	struct sockaddr_un addr = { .sun_family = AF_UNIX };
	if (strlen(argv[1]) >= sizeof addr.sun_path) {
		fprintf(stderr, "simctl: socket path too long\n");
		return 2;
	}
	strcpy(addr.sun_path, argv[1]);
	int fd = socket(AF_UNIX, SOCK_STREAM, 0);
	if (fd < 0 || connect(fd, (struct sockaddr *)&addr, sizeof addr) != 0) {
		perror("simctl: connect");
		return 1;
	}
	char line[512];
	int n = snprintf(line, sizeof line, "%s\n", argv[2]);
	if (n <= 0 || (size_t)n >= sizeof line || write(fd, line, (size_t)n) != n) {
		fprintf(stderr, "simctl: cannot send the command\n");
		close(fd);
		return 1;
	}
	struct pollfd pfd = { .fd = fd, .events = POLLIN };
	ssize_t got = 0;
	if (poll(&pfd, 1, SIMCTL_TIMEOUT_MS) == 1)
		got = read(fd, line, sizeof line - 1);
	close(fd);
	if (got <= 0) {
		fprintf(stderr, "simctl: no answer\n");
		return 1;
	}
	line[got] = '\0';
	fputs(line, stdout);
	return strncmp(line, "ok", 2) == 0 ? 0 : 1;
}
