/* SPDX-License-Identifier: Apache-2.0 */
/* Test partition for the hardening system tests: the module's Arguments pick one thing it
 * does, well-behaved or an attack on the SKE through what the SKE shares with it.
 *
 *   Arguments="quiet"         goes to NORMAL and does nothing (a bystander, a destination)
 *   Arguments="truncate"      ftruncate()s each of its descriptors 3..10 (its control block
 *                             and ports) to 0 bytes, from a constructor and again from main()
 *                             (a system partition: a file call of any other is refused), then
 *                             sends a message on its queuing source port OUT
 *   Arguments="fork"          tries to start a child process that would run on, in its
 *                             process group
 *   Arguments="fork_early"    the same from a constructor, before the APEX library attaches
 *                             if that constructor runs first
 *   Arguments="outside"       hands the CPU back at every grant and computes on regardless
 *   Arguments="burn MS"       computes MS ms of CPU at each release of its periodic process
 *   Arguments="spin"          computes forever in its initialisation process
 *   Arguments="restart FLAG"  creates the file FLAG and asks for a COLD_START; started again,
 *                             it finds FLAG and exits before attaching (status 5)
 *   Arguments="qsend"         sends one message on each of its queuing ports Q1 and Q2
 *   Arguments="qrecv T1 T2"   one process per port Q1_IN, Q2_IN waits for a message with a
 *                             time-out of T1, T2 ms and reports what it got
 *   Arguments="sample"        writes one message on its sampling source port S
 *   Arguments="future"        the same, then stamps it far in the future through its own
 *                             mapping of the port memory
 *   Arguments="read"          reads its sampling destination port S_IN once and reports
 *   Arguments="print"         prints a line on its standard output
 *   Arguments="scribble"      writes garbage where the SKE reads it, through its own mappings:
 *                             events it could not have sent into its event ring, indices
 *                             out of range into its queuing source port Q (descriptor 4) and
 *                             its destination Q1_IN's consumer index; in the next frame an
 *                             event ring claiming more events than it holds; in the one
 *                             after, a count of lost events, and it reports "ring in order"
 */
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "ARINC653.h"
#include "ske_abi.h"

static ske_ctl_t *ctl; /* "outside", "scribble": its own mapping of the control block */
static ske_queue_hdr_t *own_queue; /* "scribble": its own mapping of its queuing port Q */

static void report(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void report(const char *fmt, ...)
{
    char buf[MAX_ERROR_MESSAGE_SIZE];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (n < 0)
        return;
    if (n >= (int)sizeof buf)
        n = (int)sizeof buf - 1;
    RETURN_CODE_TYPE rc;
    REPORT_APPLICATION_MESSAGE((MESSAGE_ADDR_TYPE)buf, n, &rc);
}

static const char *rc_name(RETURN_CODE_TYPE rc)
{
    static const char *const names[] = {"NO_ERROR",      "NO_ACTION",      "NOT_AVAILABLE",
                                        "INVALID_PARAM", "INVALID_CONFIG", "INVALID_MODE",
                                        "TIMED_OUT"};
    return (unsigned)rc < sizeof names / sizeof names[0] ? names[rc] : "?";
}

static void need(RETURN_CODE_TYPE rc, const char *what)
{
    if (rc != NO_ERROR) {
        fprintf(stderr, "sys_hardening: %s: return code %s\n", what, rc_name(rc));
        exit(1);
    }
}

static int64_t cpu_ns(clockid_t clock)
{
    struct timespec ts;
    clock_gettime(clock, &ts);
    return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

static ske_sampling_hdr_t *own_port; /* "future" only: its own mapping of its port */

/* "truncate" only: ftruncate(fd, 0) of the descriptors 3..10, from the constructor (early)
 * and from main() (late): the errno of each, 0 = done. */
enum { TRUNCATE_FIRST = 3, TRUNCATE_LAST = 10 };
static int truncate_early[TRUNCATE_LAST + 1], truncate_late[TRUNCATE_LAST + 1];
static int early_attached = -1; /* whether the APEX library had attached when it ran */

static void truncate_all(int *result)
{
    for (int fd = TRUNCATE_FIRST; fd <= TRUNCATE_LAST; fd++)
        result[fd] = ftruncate(fd, 0) == 0 ? 0 : errno;
}

static void __attribute__((noreturn)) wait_forever(void)
{
    for (;;)
        pause(); /* stays in the partition's process group */
}

/* A constructor of the first priority a program may use, which the APEX library's attachment
 * has too: it runs before the attachment only if the linker puts it first (glibc hands
 * constructors the program's arguments). Before it, the partition still holds what the SKE
 * gave it: descriptor 3 the control block, 4, 5, ... its ports in the order the module
 * declares them, under the SKE's loader filter; after it, none of them (the library closes
 * them once mapped), under its own filter. */
__attribute__((constructor(101))) static void before_attach(int argc, char **argv)
{
    const char *what = argc >= 2 ? argv[1] : "";
    if (strcmp(what, "restart") == 0 && argc >= 3) {
        /* Started before: leave without attaching, as a program that cannot start would. */
        if (access(argv[2], F_OK) == 0)
            _exit(5);
        int fd = open(argv[2], O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
        if (fd < 0)
            _exit(6);
        close(fd);
    } else if (strcmp(what, "outside") == 0 || strcmp(what, "scribble") == 0) {
        void *m = mmap(NULL, sizeof(ske_ctl_t), PROT_READ | PROT_WRITE, MAP_SHARED, 3, 0);
        if (m == MAP_FAILED)
            _exit(7);
        ctl = m;
        if (what[0] == 's') {
            m = mmap(NULL, sizeof *own_queue, PROT_READ | PROT_WRITE, MAP_SHARED, 4, 0);
            if (m == MAP_FAILED)
                _exit(7);
            own_queue = m;
        }
    } else if (strcmp(what, "truncate") == 0) {
        /* The SKE maps the same memory: shrunk under it, its next access would fault. The
         * library takes the descriptor number out of the environment once attached. */
        early_attached = getenv(SKE_ENV_CTL_FD) == NULL;
        truncate_all(truncate_early);
    } else if (strcmp(what, "fork_early") == 0) {
        if (getenv(SKE_ENV_CTL_FD) == NULL)
            report("fork_early: the APEX library had attached"); /* it can report by now */
        if (fork() == 0)
            wait_forever();
    } else if (strcmp(what, "future") == 0) {
        struct stat st;
        void *m = fstat(4, &st) == 0 ? mmap(NULL, (size_t)st.st_size, PROT_READ | PROT_WRITE,
                                            MAP_SHARED, 4, 0)
                                     : MAP_FAILED;
        if (m == MAP_FAILED)
            _exit(7);
        own_port = m;
    }
}

/* ---- attacks on the SKE ------------------------------------------------------------------ */

static void truncate_ports(void)
{
    truncate_all(truncate_late);
    report("early: the APEX library %s attached", early_attached ? "had" : "had not");
    int truncated = 0;
    for (int fd = TRUNCATE_FIRST; fd <= TRUNCATE_LAST; fd++) {
        report("early ftruncate(%d): %s", fd,
               truncate_early[fd] ? strerror(truncate_early[fd]) : "done");
        report("late ftruncate(%d): %s", fd,
               truncate_late[fd] ? strerror(truncate_late[fd]) : "done");
        truncated += (truncate_early[fd] == 0) + (truncate_late[fd] == 0);
    }
    report("truncated %d descriptors", truncated);
    QUEUING_PORT_ID_TYPE out;
    RETURN_CODE_TYPE rc;
    CREATE_QUEUING_PORT("OUT", 16, 4, SOURCE, FIFO, &out, &rc);
    need(rc, "CREATE_QUEUING_PORT OUT");
    SEND_QUEUING_MESSAGE(out, (MESSAGE_ADDR_TYPE) "intact", 6, 0, &rc);
    need(rc, "SEND_QUEUING_MESSAGE");
}

static void fork_child(void)
{
    pid_t child = fork();
    if (child == 0)
        wait_forever();
    report("child %d", (int)child);
}

/* Hands the CPU back at once in every window, the way the library does (yield_seq =
 * grant_seq), but never waits for the next grant: it computes between its windows. */
static void __attribute__((noreturn)) compute_outside(void)
{
    volatile uint64_t sink = 0;
    for (;;) {
        uint32_t g = atomic_load_explicit(&ctl->grant_seq, memory_order_acquire);
        if (atomic_load(&ctl->yield_seq) != g) {
            atomic_store(&ctl->yield_seq, g);
            if (atomic_load(&ctl->ske_sleeping))
                ske_futex_wake(&ctl->yield_seq);
        }
        for (int i = 0; i < 1000; i++)
            sink++;
    }
}

static void __attribute__((noreturn)) spin(void)
{
    volatile uint64_t sink = 0;
    for (;;)
        sink++;
}

/* Puts a stamp far in the future on the latest message of its sampling source port,
 * through its own mapping of the port memory. */
static void stamp_future(uint32_t max_size)
{
    ske_sampling_hdr_t *h = own_port;
    if (h->max_size != max_size) {
        report("future: descriptor 4 is not the sampling port");
        return;
    }
    uint32_t seq = atomic_load(&h->seq);
    ske_slot_hdr_t *slot = (ske_slot_hdr_t *)((char *)h + sizeof *h +
                                              (seq & 1u) * ske_slot_stride(max_size));
    slot->t_ns = INT64_MAX / 2;
    report("future: message %u stamped %lld", seq, (long long)slot->t_ns);
}

/* Puts an event into its ring as the library would, whatever it says. */
static void put_event(int64_t t_ns, uint32_t kind, int32_t a, int32_t b, uint32_t len,
                      const char *text)
{
    uint32_t head = atomic_load(&ctl->ev_head);
    ske_event_t *e = &ctl->ev[head % SKE_EVENT_RING];
    *e = (ske_event_t){.t_ns = t_ns, .kind = kind, .a = a, .b = b, .len = len};
    size_t n = strlen(text) < sizeof e->text ? strlen(text) : sizeof e->text;
    memcpy(e->text, text, n);
    if (n < sizeof e->text)
        memset(e->text + n, 'x', sizeof e->text - n);
    atomic_store_explicit(&ctl->ev_head, head + 1, memory_order_release);
}

static void scribble(void)
{
    int64_t now = atomic_load(&ctl->win_start_ns);
    put_event(now, SKE_EV_MODE, 9, 3, 0, ""); /* no such mode */
    put_event(now, SKE_EV_PORT_VALIDITY, 42, 1, 0, ""); /* no such port */
    put_event(now, SKE_EV_HM, 0, 1, SKE_EVENT_TEXT, "no such error");
    put_event(now, SKE_EV_HM, 2, 1, 3, "short"); /* no room for a process name */
    put_event(now, 99, 0, 0, 0, ""); /* no such kind */
    put_event(now + 1000000000000LL, SKE_EV_APP_MESSAGE, 0, 0, 15, "from the future");
    put_event(now, SKE_EV_APP_MESSAGE, 0, 0, 100000, "long"); /* longer than its text */
    /* Its source queue claims more messages than it holds; its destination's consumer index
     * points past what was ever delivered. */
    atomic_store(&own_queue->head, atomic_load(&own_queue->tail) + 1000);
    atomic_fetch_add(&ctl->ports[1].rx_tail, 77);
}

static void scribble_later(void)
{
    RETURN_CODE_TYPE rc;
    PERIODIC_WAIT(&rc); /* released with NORMAL, in the window of the scribbles above */
    atomic_fetch_add(&ctl->ev_head, SKE_EVENT_RING + 5);
    PERIODIC_WAIT(&rc);
    atomic_store(&ctl->ev_dropped, 3);
    report("ring in order");
    for (;;)
        PERIODIC_WAIT(&rc);
}

/* ---- well-behaved services ----------------------------------------------------------------- */

static long burn_ms;
static QUEUING_PORT_ID_TYPE q_in[2];
static SYSTEM_TIME_TYPE q_timeout[2];

static void burn(void)
{
    RETURN_CODE_TYPE rc;
    for (;;) {
        int64_t until = cpu_ns(CLOCK_THREAD_CPUTIME_ID) + burn_ms * 1000000LL;
        volatile uint64_t sink = 0;
        while (cpu_ns(CLOCK_THREAD_CPUTIME_ID) < until)
            sink++;
        PERIODIC_WAIT(&rc);
    }
}

static void receive(int i)
{
    APEX_BYTE buf[16];
    MESSAGE_SIZE_TYPE len = 0;
    RETURN_CODE_TYPE rc, trc;
    SYSTEM_TIME_TYPE t0, t1;
    GET_TIME(&t0, &trc);
    RECEIVE_QUEUING_MESSAGE(q_in[i], q_timeout[i], buf, &len, &rc);
    GET_TIME(&t1, &trc);
    if (rc == NO_ERROR)
        report("Q%d_IN: NO_ERROR '%.*s' waited from %lld to %lld", i + 1, (int)len,
               (const char *)buf, (long long)t0, (long long)t1);
    else
        report("Q%d_IN: %s waited from %lld to %lld", i + 1, rc_name(rc), (long long)t0,
               (long long)t1);
    STOP_SELF();
}

static void receive_1(void) { receive(0); }
static void receive_2(void) { receive(1); }

static void start_process(const char *name, void (*entry)(void), SYSTEM_TIME_TYPE period)
{
    RETURN_CODE_TYPE rc;
    PROCESS_ATTRIBUTE_TYPE a = {.PERIOD = period, .TIME_CAPACITY = period,
                                .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)entry, .STACK_SIZE = 65536,
                                .BASE_PRIORITY = 10, .DEADLINE = SOFT};
    strncpy(a.NAME, name, sizeof a.NAME - 1);
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&a, &pid, &rc);
    need(rc, "CREATE_PROCESS");
    START(pid, &rc);
    need(rc, "START");
}

int main(int argc, char **argv)
{
    RETURN_CODE_TYPE rc;
    const char *mode = argc >= 2 ? argv[1] : "quiet";
    if (strcmp(mode, "truncate") == 0) {
        truncate_ports();
    } else if (strcmp(mode, "fork") == 0) {
        fork_child();
    } else if (strcmp(mode, "fork_early") == 0) {
        report("forked before attaching"); /* only if its constructor's fork() went through */
    } else if (strcmp(mode, "outside") == 0) {
        compute_outside();
    } else if (strcmp(mode, "spin") == 0) {
        report("spinning");
        spin();
    } else if (strcmp(mode, "burn") == 0 && argc >= 3) {
        burn_ms = strtol(argv[2], NULL, 10);
        PARTITION_STATUS_TYPE st;
        GET_PARTITION_STATUS(&st, &rc);
        start_process("burn", burn, st.PERIOD);
    } else if (strcmp(mode, "restart") == 0) {
        report("started: asking for COLD_START");
        SET_PARTITION_MODE(COLD_START, &rc); /* does not return: the SKE starts it again */
    } else if (strcmp(mode, "qsend") == 0) {
        QUEUING_PORT_ID_TYPE q1, q2;
        CREATE_QUEUING_PORT("Q1", 16, 4, SOURCE, FIFO, &q1, &rc);
        need(rc, "CREATE_QUEUING_PORT Q1");
        CREATE_QUEUING_PORT("Q2", 16, 4, SOURCE, FIFO, &q2, &rc);
        need(rc, "CREATE_QUEUING_PORT Q2");
        SEND_QUEUING_MESSAGE(q1, (MESSAGE_ADDR_TYPE) "one", 3, 0, &rc);
        need(rc, "SEND_QUEUING_MESSAGE Q1");
        SEND_QUEUING_MESSAGE(q2, (MESSAGE_ADDR_TYPE) "two", 3, 0, &rc);
        need(rc, "SEND_QUEUING_MESSAGE Q2");
        SYSTEM_TIME_TYPE now;
        GET_TIME(&now, &rc);
        report("sent at %lld", (long long)now);
    } else if (strcmp(mode, "qrecv") == 0 && argc >= 4) {
        for (int i = 0; i < 2; i++) {
            char name[8];
            snprintf(name, sizeof name, "Q%d_IN", i + 1);
            CREATE_QUEUING_PORT(name, 16, 4, DESTINATION, FIFO, &q_in[i], &rc);
            need(rc, "CREATE_QUEUING_PORT Qn_IN");
            q_timeout[i] = strtoll(argv[2 + i], NULL, 10) * 1000000LL;
        }
        start_process("receive_1", receive_1, INFINITE_TIME_VALUE);
        start_process("receive_2", receive_2, INFINITE_TIME_VALUE);
    } else if (strcmp(mode, "sample") == 0 || strcmp(mode, "future") == 0) {
        SAMPLING_PORT_ID_TYPE s;
        CREATE_SAMPLING_PORT("S", 16, SOURCE, 100000000, &s, &rc);
        need(rc, "CREATE_SAMPLING_PORT S");
        WRITE_SAMPLING_MESSAGE(s, (MESSAGE_ADDR_TYPE) "sample", 6, &rc);
        need(rc, "WRITE_SAMPLING_MESSAGE");
        if (strcmp(mode, "future") == 0)
            stamp_future(16);
    } else if (strcmp(mode, "read") == 0) {
        SAMPLING_PORT_ID_TYPE s;
        CREATE_SAMPLING_PORT("S_IN", 16, DESTINATION, 100000000, &s, &rc);
        need(rc, "CREATE_SAMPLING_PORT S_IN");
        APEX_BYTE buf[16];
        MESSAGE_SIZE_TYPE len = 0;
        VALIDITY_TYPE v = INVALID;
        READ_SAMPLING_MESSAGE(s, buf, &len, &v, &rc);
        report("S_IN: %s %s '%.*s'", rc_name(rc), v == VALID ? "VALID" : "INVALID",
               rc == NO_ERROR ? (int)len : 0, (const char *)buf);
    } else if (strcmp(mode, "scribble") == 0) {
        scribble();
        PARTITION_STATUS_TYPE st;
        GET_PARTITION_STATUS(&st, &rc);
        start_process("scribble", scribble_later, st.PERIOD);
    } else if (strcmp(mode, "print") == 0) {
        printf("sys_hardening: a line on standard output\n");
        fflush(stdout);
    } else if (strcmp(mode, "quiet") != 0) {
        fprintf(stderr, "sys_hardening: unknown arguments\n");
        return 1;
    }
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
