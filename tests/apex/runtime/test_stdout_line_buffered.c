/* SPDX-License-Identifier: Apache-2.0 */
/* A partition's standard output is line-buffered from before main(): three partitions print
 * long lines through stdio in turns, one is then killed (SIGKILL, as the health monitor or a
 * restart ends a process), one goes IDLE (ima-ske ends its process), one goes on. Every
 * complete line printed must reach ima-ske's standard output whole. */
#include <signal.h>

#include "apex_check.h"

#define LINES_PER_WINDOW 24

static const char *who;
static int line_no;

/* About 130 bytes a line: a window's lines are more than a 4 KiB stdio buffer, so that full
 * buffering would flush in the middle of a line. */
static void print_lines(int n)
{
    for (int i = 0; i < n; i++, line_no++)
        printf("%s line %03d %s\n", who, line_no,
               "................................................................................"
               "..................................");
}

static void printer(void)
{
    RETURN_CODE_TYPE rc;
    for (int window = 0;; window++) {
        print_lines(LINES_PER_WINDOW);
        if (window == 2 && strcmp(who, "killed") == 0) {
            fputs("killed partial line without its end", stdout); /* may be lost: no newline */
            report("killing itself after %d lines", line_no);
            raise(SIGKILL);
        }
        if (window == 2 && strcmp(who, "idled") == 0) {
            report("going idle after %d lines", line_no);
            SET_PARTITION_MODE(IDLE, &rc);
        }
        PERIODIC_WAIT(&rc);
    }
}

int main(int argc, char **argv)
{
    who = argc > 1 ? argv[1] : "unknown";
    start_new_process("printer", printer, 10, 20 * MS);
    enter_normal();
    return 1;
}
