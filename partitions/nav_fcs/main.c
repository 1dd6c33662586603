/* SPDX-License-Identifier: Apache-2.0 */
/* The nav_fcs partition: each 50 ms reads the sensor, pilot, actuator and mission ports, runs
 * the navigation and flight-control cores, writes the actuator command, status and solution. */
#include <stdio.h>
#include <string.h>

#include "ARINC653.h"
#include "fcs.h"
#include "nav.h"
#include "rpas/report.h"

#define NAV_FCS_PERIOD_NS 50000000LL

/* Port sizes are the CONTRACT's structs (rpas/ports.h); the module XML must say the same. */
_Static_assert(sizeof(rpas_gps_msg_t) == 64, "GPS_IN size");
_Static_assert(sizeof(rpas_ahrs_msg_t) == 88, "AHRS_IN size");
_Static_assert(sizeof(rpas_air_msg_t) == 40, "AIR_IN size");
_Static_assert(sizeof(rpas_pilot_msg_t) == 96, "PILOT_IN size");
_Static_assert(sizeof(rpas_act_status_msg_t) == 48, "ACT_IN size");
_Static_assert(sizeof(rpas_mission_msg_t) == 56, "MISSION_IN size");
_Static_assert(sizeof(rpas_act_cmd_msg_t) == 48, "ACT_CMD_OUT size");
_Static_assert(sizeof(rpas_fcs_status_msg_t) == 72, "FCS_STATUS_OUT size");
_Static_assert(sizeof(rpas_nav_msg_t) == 112, "NAV_OUT size");

enum { P_GPS, P_AHRS, P_AIR, P_PILOT, P_ACT, P_MISSION, P_ACT_CMD, P_STATUS, P_NAV, P_COUNT };

static const struct {
    const char *name;
    MESSAGE_SIZE_TYPE size;
    PORT_DIRECTION_TYPE dir;
    SYSTEM_TIME_TYPE refresh_ns;
} port_cfg[P_COUNT] = {
    [P_GPS] = {"GPS_IN", sizeof(rpas_gps_msg_t), DESTINATION, 600000000},
    [P_AHRS] = {"AHRS_IN", sizeof(rpas_ahrs_msg_t), DESTINATION, 100000000},
    [P_AIR] = {"AIR_IN", sizeof(rpas_air_msg_t), DESTINATION, 200000000},
    [P_PILOT] = {"PILOT_IN", sizeof(rpas_pilot_msg_t), DESTINATION, 1000000000},
    [P_ACT] = {"ACT_IN", sizeof(rpas_act_status_msg_t), DESTINATION, 200000000},
    [P_MISSION] = {"MISSION_IN", sizeof(rpas_mission_msg_t), DESTINATION, 500000000},
    [P_ACT_CMD] = {"ACT_CMD_OUT", sizeof(rpas_act_cmd_msg_t), SOURCE, 200000000},
    [P_STATUS] = {"FCS_STATUS_OUT", sizeof(rpas_fcs_status_msg_t), SOURCE, 200000000},
    [P_NAV] = {"NAV_OUT", sizeof(rpas_nav_msg_t), SOURCE, 200000000},
};

/* The partition's state: one instance, owned here; the cores take it by pointer. */
static struct {
    SAMPLING_PORT_ID_TYPE port[P_COUNT];
    nav_t nav;
    fcs_t fcs;
    nav_inputs_t nav_in;
    fcs_inputs_t fcs_in;
} app;

/* Reads one destination port into msg; true when a whole, VALID message was read. A message
 * that is not valid still updates msg (the cores ignore it). */
static bool read_port(int p, void *msg)
{
    unsigned char buf[sizeof(rpas_pilot_msg_t) > 128 ? sizeof(rpas_pilot_msg_t) : 128];
    MESSAGE_SIZE_TYPE len = 0;
    VALIDITY_TYPE v = INVALID;
    RETURN_CODE_TYPE rc;
    READ_SAMPLING_MESSAGE(app.port[p], (MESSAGE_ADDR_TYPE)buf, &len, &v, &rc);
    if (rc != NO_ERROR || len != port_cfg[p].size)
        return false;
    memcpy(msg, buf, (size_t)len);
    return v == VALID;
}

static void write_port(int p, const void *msg)
{
    RETURN_CODE_TYPE rc;
    WRITE_SAMPLING_MESSAGE(app.port[p], (MESSAGE_ADDR_TYPE)msg, port_cfg[p].size, &rc);
}

static const char *mode_name(uint32_t m)
{
    static const char *const names[] = {"INIT", "DIRECT", "AUTOPILOT", "MISSION", "CONTINGENCY"};
    return m < sizeof names / sizeof names[0] ? names[m] : "?";
}

static const char *fallback_name(uint32_t f)
{
    static const char *const names[] = {"NONE", "C2_LOST", "MISSION_STALE", "NAV_INVALID", "NO_TARGETS"};
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
        CREATE_SAMPLING_PORT(port_cfg[p].name, port_cfg[p].size, port_cfg[p].dir, port_cfg[p].refresh_ns,
                             &app.port[p], &rc);
        if (rc != NO_ERROR) {
            fail(port_cfg[p].name, rc);
            return 1;
        }
    }
    nav_init(&app.nav, NULL);
    fcs_init(&app.fcs, NULL);

    PROCESS_ATTRIBUTE_TYPE attr = {
        .PERIOD = NAV_FCS_PERIOD_NS,
        .TIME_CAPACITY = NAV_FCS_PERIOD_NS,
        .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)cycle,
        .STACK_SIZE = 262144,
        .BASE_PRIORITY = 100,
        .DEADLINE = HARD,
        .NAME = "nav_fcs",
    };
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&attr, &pid, &rc);
    if (rc != NO_ERROR) {
        fail("CREATE_PROCESS nav_fcs", rc);
        return 1;
    }
    START(pid, &rc);
    if (rc != NO_ERROR) {
        fail("START nav_fcs", rc);
        return 1;
    }
    SET_PARTITION_MODE(NORMAL, &rc);
    fail("SET_PARTITION_MODE NORMAL", rc);
    return 1;
}
