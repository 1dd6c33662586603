/* SPDX-License-Identifier: Apache-2.0 */
/* Spatial partitioning of port memory (ARINC 653 Part 1, spatial partitioning): a destination
 * partition can read a channel's memory but never write it. Scenario "writer" writes its
 * period count on a sampling port every period; "reader" reads and checks it every period;
 * "vandal" reads it too, then looks up its read-only port mapping in /proc/self/maps, tries to
 * make it writable and writes through it: the write must kill it with SIGSEGV, and the
 * channel must keep the writer's data. */
#include <errno.h>
#include <stdint.h>
#include <sys/mman.h>

#include "apex_check.h"

static SAMPLING_PORT_ID_TYPE port;

static void writer_process(void)
{
    for (uint32_t k = 0;; k++) {
        RETURN_CODE_TYPE rc;
        WRITE_SAMPLING_MESSAGE(port, (MESSAGE_ADDR_TYPE)&k, sizeof k, &rc);
        setup_rc("WRITE_SAMPLING_MESSAGE", rc);
        PERIODIC_WAIT(&rc);
    }
}

static void reader_process(void)
{
    for (int k = 0;; k++) {
        uint32_t value = UINT32_MAX;
        MESSAGE_SIZE_TYPE len;
        VALIDITY_TYPE v;
        RETURN_CODE_TYPE rc;
        char n[32];
        READ_SAMPLING_MESSAGE(port, (MESSAGE_ADDR_TYPE)&value, &len, &v, &rc);
        snprintf(n, sizeof n, "frame%d.read", k);
        check_rc(n, NO_ERROR, rc);
        snprintf(n, sizeof n, "frame%d.value", k);
        check_int(n, k, value);
        PERIODIC_WAIT(&rc);
    }
}

/* The first shared read-only mapping of a port memory object (named "ima-..." by the SKE). */
static uintptr_t find_port_mapping(char *line_out, size_t size)
{
    FILE *f = fopen("/proc/self/maps", "r");
    if (!f)
        return 0;
    char line[512];
    uintptr_t start = 0;
    while (!start && fgets(line, sizeof line, f)) {
        unsigned long lo, hi;
        char perms[8];
        if (sscanf(line, "%lx-%lx %7s", &lo, &hi, perms) == 3 && strcmp(perms, "r--s") == 0 &&
            strstr(line, "memfd:ima-")) {
            start = lo;
            snprintf(line_out, size, "%s", line);
        }
    }
    fclose(f);
    return start;
}

static void vandal_process(void)
{
    uint32_t value;
    MESSAGE_SIZE_TYPE len;
    VALIDITY_TYPE v;
    RETURN_CODE_TYPE rc;
    READ_SAMPLING_MESSAGE(port, (MESSAGE_ADDR_TYPE)&value, &len, &v, &rc);
    check_rc("vandal.read", NO_ERROR, rc);

    char line[512] = "";
    uintptr_t addr = find_port_mapping(line, sizeof line);
    check_true("vandal.found_read_only_mapping", addr != 0);
    if (!addr)
        return;
    line[strcspn(line, "\n")] = '\0';
    report("VANDAL mapping %.100s", strchr(line, '/') ? strchr(line, '/') : line);

    /* The descriptor behind the mapping is read-only: the mapping cannot become writable. */
    int r = mprotect((void *)addr, 4096, PROT_READ | PROT_WRITE);
    check_str("vandal.mprotect_write", "EACCES",
              r == 0 ? "allowed" : errno == EACCES ? "EACCES" : "other-error");

    report("VANDAL writing");
    volatile uint8_t *p = (volatile uint8_t *)addr;
    p[0] = (uint8_t)~p[0];
    report("VANDAL survived the write");
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    PORT_DIRECTION_TYPE dir = strcmp(scenario, "writer") == 0 ? SOURCE : DESTINATION;
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT(dir == SOURCE ? "SP_OUT" : "SP_IN", 4, dir, 1000 * MS, &port, &rc);
    setup_rc("CREATE_SAMPLING_PORT", rc);
    if (strcmp(scenario, "writer") == 0) {
        start_new_process("writer", writer_process, 10, 20 * MS);
    } else if (strcmp(scenario, "reader") == 0) {
        start_new_process("reader", reader_process, 10, 20 * MS);
    } else if (strcmp(scenario, "vandal") == 0) {
        PROCESS_ATTRIBUTE_TYPE a = process_attributes("vandal", vandal_process, 10,
                                                      INFINITE_TIME_VALUE, INFINITE_TIME_VALUE);
        a.STACK_SIZE = 256 * 1024;
        PROCESS_ID_TYPE id;
        CREATE_PROCESS(&a, &id, &rc);
        setup_rc("CREATE_PROCESS vandal", rc);
        START(id, &rc);
        setup_rc("START vandal", rc);
    } else {
        report("SETUP unknown scenario '%s'", scenario);
    }
    enter_normal();
    return 1;
}
