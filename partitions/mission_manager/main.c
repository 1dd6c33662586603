/* SPDX-License-Identifier: Apache-2.0 */
/* The mission manager's APEX main: each period it takes the plan io reassembled from the
 * uplink (queuing port PLAN_IN), reads its node's navigation solution, flight-control status,
 * the pilot's uplink, io's plan agreement and commands, the traffic report and the radar
 * altimeter, runs the core
 * (mm.c) and writes the targets for nav_fcs (MISSION_OUT) and its status for the downlink
 * (MM_STATUS_OUT). Its ports and process come from the contract generated from the model. */
#include <stdio.h>
#include <string.h>

#include "ARINC653.h"
#include "mission_manager_ports.h"
#include "mm.h"
#include "rpas/port.h"
#include "rpas/process.h"
#include "rpas/report.h"

enum {
    P_NAV = MISSION_MANAGER_PORT_NAV_IN,
    P_STATUS = MISSION_MANAGER_PORT_FCS_STATUS_IN,
    P_PILOT = MISSION_MANAGER_PORT_PILOT_IN,
    P_CMD = MISSION_MANAGER_PORT_MM_CMD_IN,
    P_TRAFFIC = MISSION_MANAGER_PORT_TRAFFIC_IN,
    P_RADALT = MISSION_MANAGER_PORT_RADALT_IN,
    P_PLAN = MISSION_MANAGER_PORT_PLAN_IN,
    P_MISSION = MISSION_MANAGER_PORT_MISSION_OUT,
    P_MM_STATUS = MISSION_MANAGER_PORT_MM_STATUS_OUT,
    P_COUNT = MISSION_MANAGER_PORT_COUNT
};

/* PLAN_IN's message: the plan's CRC-32 as the uplink gave it, its length, then the image. */
#define PLAN_MSG_MAX (8 + RPAS_PLAN_MAX_BYTES)

static struct {
    long id[P_COUNT];
    mm_t mm;
    mm_inputs_t in;
    unsigned char plan_msg[PLAN_MSG_MAX];
} app;

static bool read_port(int p, void *msg)
{
    unsigned char buf[128];
    _Static_assert(sizeof(rpas_pilot_msg_t) <= sizeof buf && sizeof(rpas_nav_msg_t) <= sizeof buf,
                   "read_port's buffer holds every message the mission manager reads");
    MESSAGE_SIZE_TYPE len = 0;
    VALIDITY_TYPE v = INVALID;
    RETURN_CODE_TYPE rc;
    READ_SAMPLING_MESSAGE((SAMPLING_PORT_ID_TYPE)app.id[p], (MESSAGE_ADDR_TYPE)buf, &len, &v, &rc);
    if (rc != NO_ERROR || len != mission_manager_port_spec[p].size)
        return false;
    memcpy(msg, buf, (size_t)len);
    return v == VALID;
}

/* The newest plan in the queue (older ones are superseded), or none (in->plan NULL). */
static void receive_plan(void)
{
    for (;;) {
        MESSAGE_SIZE_TYPE len = 0;
        RETURN_CODE_TYPE rc;
        RECEIVE_QUEUING_MESSAGE((QUEUING_PORT_ID_TYPE)app.id[P_PLAN], 0,
                                (MESSAGE_ADDR_TYPE)app.plan_msg, &len, &rc);
        if (rc != NO_ERROR && rc != INVALID_CONFIG) /* INVALID_CONFIG: a message after a loss */
            break;
        if (len < 8 || len > (MESSAGE_SIZE_TYPE)sizeof app.plan_msg)
            continue;
        memcpy(&app.in.plan_crc, app.plan_msg, 4);
        app.in.plan = app.plan_msg + 8;
        app.in.plan_len = (size_t)len - 8;
    }
}

static void cycle(void)
{
    uint32_t last_state = UINT32_MAX;
    int last_leg = -2;
    for (;;) {
        RETURN_CODE_TYPE rc;
        SYSTEM_TIME_TYPE now = 0;
        GET_TIME(&now, &rc);
        mm_inputs_t *in = &app.in;
        in->nav_ok = read_port(P_NAV, &in->nav);
        in->fcs_ok = read_port(P_STATUS, &in->fcs);
        read_port(P_PILOT, &in->pilot); /* its time, valid or not: the C2 link's last sign */
        in->cmd_ok = read_port(P_CMD, &in->cmd);
        in->traffic_ok = read_port(P_TRAFFIC, &in->traffic);
        in->radalt_ok = read_port(P_RADALT, &in->radalt);
        in->plan = NULL;
        receive_plan();

        rpas_mission_msg_t target;
        rpas_mm_status_msg_t status;
        if (mm_step(&app.mm, in, now, &target, &status))
            WRITE_SAMPLING_MESSAGE((SAMPLING_PORT_ID_TYPE)app.id[P_MISSION],
                                   (MESSAGE_ADDR_TYPE)&target, sizeof target, &rc);
        WRITE_SAMPLING_MESSAGE((SAMPLING_PORT_ID_TYPE)app.id[P_MM_STATUS],
                               (MESSAGE_ADDR_TYPE)&status, sizeof status, &rc);
        if (app.mm.event[0])
            rpas_report("mission_manager: %s", app.mm.event);
        if (status.state != last_state || status.leg != last_leg) {
            rpas_report("mission_manager: %s leg %d %s", mm_state_name(status.state),
                        (int)status.leg, mm_leg_name((int)status.leg_type));
            last_state = status.state;
            last_leg = status.leg;
        }
        PERIODIC_WAIT(&rc);
    }
}

static void fail(const char *what, RETURN_CODE_TYPE rc)
{
    rpas_report("mission_manager: init failed: %s rc=%d", what, (int)rc);
    fprintf(stderr, "mission_manager: %s failed: return code %d\n", what, (int)rc);
    SET_PARTITION_MODE(IDLE, &rc);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    const char *bad_port = rpas_create_ports(mission_manager_port_spec, P_COUNT, app.id, &rc);
    if (bad_port) {
        fail(bad_port, rc);
        return 1;
    }
    mm_init(&app.mm, NULL);
    const rpas_process_spec_t *ps = &mission_manager_process_spec[MISSION_MANAGER_PROCESS_MISSION];
    PROCESS_ID_TYPE pid;
    rpas_start_process(ps, cycle, &pid, &rc);
    if (rc != NO_ERROR) {
        fail(ps->name, rc);
        return 1;
    }
    SET_PARTITION_MODE(NORMAL, &rc);
    fail("SET_PARTITION_MODE NORMAL", rc);
    return 1;
}
