/* SPDX-License-Identifier: Apache-2.0 */
/* The flight data recorder's APEX main: each period it records its node's navigation
 * solution, flight-control status and mission targets, then every health-monitor decision
 * the module's HM log port holds, into the output file the SKE opened for it (its only
 * writable file: it may open none). A write that fails (a full disk, an I/O error) is the
 * recorder's own error: RAISE_APPLICATION_ERROR, and its HM table restarts it. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ARINC653.h"
#include "fdr.h"
#include "fdr_ports.h"
#include "rpas/port.h"
#include "rpas/process.h"
#include "rpas/report.h"

enum {
    P_NAV = FDR_PORT_NAV_IN,
    P_STATUS = FDR_PORT_FCS_STATUS_IN,
    P_MISSION = FDR_PORT_MISSION_IN,
    P_HM = FDR_PORT_HM_LOG_IN,
    P_COUNT = FDR_PORT_COUNT
};

#define HM_PER_PERIOD 16 /* decisions recorded per period at most: the rest wait in the port */

static struct {
    int fd;
    long ids[P_COUNT];
    fdr_t rec;
    uint8_t buf[(2 + HM_PER_PERIOD) * FDR_RECORD_SIZE];
} app = {.fd = -1};

static bool read_sampling(int p, void *msg)
{
    uint8_t buf[256];
    MESSAGE_SIZE_TYPE len = 0;
    VALIDITY_TYPE v = INVALID;
    RETURN_CODE_TYPE rc;
    READ_SAMPLING_MESSAGE((SAMPLING_PORT_ID_TYPE)app.ids[p], (MESSAGE_ADDR_TYPE)buf, &len, &v,
                          &rc);
    if (rc != NO_ERROR || len != fdr_port_spec[p].size || len < 0 || (size_t)len > sizeof buf)
        return false;
    memcpy(msg, buf, (size_t)len);
    return v == VALID;
}

/* Writes n bytes whole; on failure the recorder's HM decides (its table restarts it). */
static void put(const uint8_t *data, size_t n)
{
    size_t done = 0;
    while (done < n) {
        ssize_t w = write(app.fd, data + done, n - done);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            char msg[96];
            int len = snprintf(msg, sizeof msg, "fdr: writing the recording failed: %s",
                               w < 0 ? strerror(errno) : "nothing written");
            RETURN_CODE_TYPE rc;
            RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE)msg,
                                    (ERROR_MESSAGE_SIZE_TYPE)len, &rc);
            return;
        }
        done += (size_t)w;
    }
}

static void cycle(void)
{
    for (;;) {
        RETURN_CODE_TYPE rc;
        SYSTEM_TIME_TYPE now = 0;
        GET_TIME(&now, &rc);
        rpas_nav_msg_t nav;
        rpas_fcs_status_msg_t st;
        rpas_mission_msg_t mis;
        bool have_nav = read_sampling(P_NAV, &nav);
        bool have_st = read_sampling(P_STATUS, &st);
        bool have_mis = read_sampling(P_MISSION, &mis);
        size_t n = 0;
        fdr_frame_record(&app.rec, now, have_nav ? &nav : NULL, have_st ? &st : NULL,
                         have_mis ? &mis : NULL, app.buf);
        n += FDR_RECORD_SIZE;
        for (int k = 0; k < HM_PER_PERIOD; k++) {
            ske_hm_log_t hm;
            MESSAGE_SIZE_TYPE len = 0;
            RECEIVE_QUEUING_MESSAGE((QUEUING_PORT_ID_TYPE)app.ids[P_HM], 0,
                                    (MESSAGE_ADDR_TYPE)&hm, &len, &rc);
            if (rc != NO_ERROR && rc != INVALID_CONFIG) /* INVALID_CONFIG: some were lost */
                break;
            if (len != (MESSAGE_SIZE_TYPE)sizeof hm)
                continue;
            fdr_hm_record(&app.rec, now, &hm, app.buf + n);
            n += FDR_RECORD_SIZE;
        }
        put(app.buf, n);
        PERIODIC_WAIT(&rc);
    }
}

static void fail(const char *what, RETURN_CODE_TYPE rc)
{
    rpas_report("fdr: init failed: %s rc=%d", what, (int)rc);
    fprintf(stderr, "fdr: %s failed: return code %d\n", what, (int)rc);
    SET_PARTITION_MODE(IDLE, &rc);
}

int main(int argc, char **argv)
{
    RETURN_CODE_TYPE rc;
    const char *node = argc > 1 ? argv[1] : ""; /* its node's name: the model's {node} */
    const char *fd_text = getenv(SKE_ENV_OUTPUT_FD);
    app.fd = fd_text ? atoi(fd_text) : -1;
    if (app.fd <= STDERR_FILENO) {
        fail("no output file (ima:Linux OutputFile)", INVALID_CONFIG);
        return 1;
    }
    const char *bad_port = rpas_create_ports(fdr_port_spec, P_COUNT, app.ids, &rc);
    if (bad_port) {
        fail(bad_port, rc);
        return 1;
    }
    PARTITION_STATUS_TYPE status;
    GET_PARTITION_STATUS(&status, &rc);
    fdr_init(&app.rec, FDR_PARTITION_PERIOD_NS);
    /* A record cut short by the last process (a crash mid-write, a full disk) is padded to a
     * whole record, so that every record of this process starts on a record boundary. */
    struct stat sb;
    if (fstat(app.fd, &sb) == 0 && sb.st_size % FDR_RECORD_SIZE) {
        static const uint8_t zeros[FDR_RECORD_SIZE];
        put(zeros, FDR_RECORD_SIZE - (size_t)(sb.st_size % FDR_RECORD_SIZE));
    }
    SYSTEM_TIME_TYPE now = 0;
    GET_TIME(&now, &rc);
    uint8_t start[FDR_RECORD_SIZE];
    fdr_start_record(&app.rec, now, (uint32_t)status.START_CONDITION,
                     (uint32_t)status.OPERATING_MODE, node, start);
    put(start, sizeof start);

    const rpas_process_spec_t *ps = &fdr_process_spec[FDR_PROCESS_RECORD];
    PROCESS_ID_TYPE pid;
    rpas_start_process(ps, cycle, &pid, &rc);
    if (rc != NO_ERROR) {
        fail(ps->name, rc);
        return 1;
    }
    SET_PARTITION_MODE(NORMAL, &rc);
    return 0;
}
