/* SPDX-License-Identifier: Apache-2.0 */
/* The nav_fcs partition's APEX main: each period reads the sensor, pilot, actuator and mission
 * ports, runs the navigation and flight-control cores, writes the actuator command, status and
 * solution. Its ports and process come from the contract generated from the system model. */
#include <stdio.h>
#include <string.h>

#include "ARINC653.h"
#include "fcs.h"
#include "nav.h"
#include "nav_fcs_ports.h"
#include "rpas/process.h"
#include "rpas/report.h"

/* Port indices: the contract's (nav_fcs_ports.h, generated from the system model). */
enum {
    P_GPS = NAV_FCS_PORT_GPS_IN,
    P_AHRS = NAV_FCS_PORT_AHRS_IN,
    P_AIR = NAV_FCS_PORT_AIR_IN,
    P_PILOT = NAV_FCS_PORT_PILOT_IN,
    P_ACT = NAV_FCS_PORT_ACT_IN,
    P_MISSION = NAV_FCS_PORT_MISSION_IN,
    P_ACT_CMD = NAV_FCS_PORT_ACT_CMD_OUT,
    P_STATUS = NAV_FCS_PORT_FCS_STATUS_OUT,
    P_NAV = NAV_FCS_PORT_NAV_OUT,
    P_COUNT = NAV_FCS_PORT_COUNT
};

/* The partition's state: one instance, owned here; the cores take it by pointer. */
static struct {
    SAMPLING_PORT_ID_TYPE port[P_COUNT];
    nav_t nav;
    fcs_t fcs;
    nav_inputs_t nav_in;
    fcs_inputs_t fcs_in;
} app;

/* Reads one destination port into msg (a struct of the port's size, as the contract checks);
 * true when a whole, VALID message was read. A message that is not valid still updates msg
 * (the cores ignore it). */
static bool read_port(int p, void *msg)
{
    unsigned char buf[128];
    _Static_assert(sizeof(rpas_pilot_msg_t) <= sizeof buf && sizeof(rpas_nav_msg_t) <= sizeof buf,
                   "read_port's buffer holds every message nav_fcs reads");
    MESSAGE_SIZE_TYPE len = 0;
    VALIDITY_TYPE v = INVALID;
    RETURN_CODE_TYPE rc;
    READ_SAMPLING_MESSAGE(app.port[p], (MESSAGE_ADDR_TYPE)buf, &len, &v, &rc);
    if (rc != NO_ERROR || len != nav_fcs_port_spec[p].size)
        return false;
    memcpy(msg, buf, (size_t)len);
    return v == VALID;
}

static void write_port(int p, const void *msg)
{
    RETURN_CODE_TYPE rc;
    WRITE_SAMPLING_MESSAGE(app.port[p], (MESSAGE_ADDR_TYPE)msg, nav_fcs_port_spec[p].size, &rc);
}

static const char *mode_name(uint32_t m)
{
    static const char *const names[] = {"INIT", "DIRECT", "AUTOPILOT", "MISSION", "CONTINGENCY"};
    return m < sizeof names / sizeof names[0] ? names[m] : "?";
}

static const char *fallback_name(uint32_t f)
{
    static const char *const names[] = {"NONE",        "C2_LOST",    "MISSION_STALE",
                                        "NAV_INVALID", "NO_TARGETS", "SENSOR_LOST"};
    return f < sizeof names / sizeof names[0] ? names[f] : "?";
}

static void cycle(void)
{
    uint32_t last_mode = UINT32_MAX, last_fb = UINT32_MAX;
    for (;;) {
        RETURN_CODE_TYPE rc;
        SYSTEM_TIME_TYPE now = 0;
        GET_TIME(&now, &rc);

        nav_inputs_t *ni = &app.nav_in;
        fcs_inputs_t *fi = &app.fcs_in;
        ni->gps_ok = read_port(P_GPS, &ni->gps);
        ni->ahrs_ok = read_port(P_AHRS, &ni->ahrs);
        ni->air_ok = read_port(P_AIR, &ni->air);
        fi->pilot_ok = read_port(P_PILOT, &fi->pilot);
        fi->act_ok = read_port(P_ACT, &fi->act);
        fi->mission_ok = read_port(P_MISSION, &fi->mission);
        fi->ahrs = ni->ahrs;

        rpas_nav_msg_t nav;
        rpas_act_cmd_msg_t cmd;
        rpas_fcs_status_msg_t st;
        nav_update(&app.nav, ni, now, &nav);
        fcs_step(&app.fcs, fi, &nav, now, &cmd, &st);

        write_port(P_ACT_CMD, &cmd);
        write_port(P_STATUS, &st);
        write_port(P_NAV, &nav);

        if (st.mode != last_mode || st.fallback != last_fb) {
            rpas_report("nav_fcs: mode %s (asked %s) fallback %s nav 0x%x", mode_name(st.mode),
                   mode_name(st.req_mode), fallback_name(st.fallback), (unsigned)st.nav_flags);
            last_mode = st.mode;
            last_fb = st.fallback;
        }
        PERIODIC_WAIT(&rc);
    }
}

static void fail(const char *what, RETURN_CODE_TYPE rc)
{
    rpas_report("nav_fcs: init failed: %s rc=%d", what, (int)rc);
    fprintf(stderr, "nav_fcs: %s failed: return code %d\n", what, (int)rc);
    SET_PARTITION_MODE(IDLE, &rc);
}

/* The initialisation process: ports, the cores, the periodic process. */
int main(void)
{
    RETURN_CODE_TYPE rc;
    for (int p = 0; p < P_COUNT; p++) {
        const rpas_port_spec_t *ps = &nav_fcs_port_spec[p];
        CREATE_SAMPLING_PORT((char *)ps->name, ps->size, ps->direction, ps->refresh_ns, &app.port[p], &rc);
        if (rc != NO_ERROR) {
            fail(ps->name, rc);
            return 1;
        }
    }
    nav_init(&app.nav, NULL);
    fcs_init(&app.fcs, NULL);

    const rpas_process_spec_t *ps = &nav_fcs_process_spec[NAV_FCS_PROCESS_NAV_FCS];
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
