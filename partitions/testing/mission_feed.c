/* SPDX-License-Identifier: Apache-2.0 */
/* Test partition standing in for the mission manager: writes MISSION targets on MISSION_OUT
 * every major frame until a given time, then falls silent, so that the flight-control
 * partition's use of mission targets and its fallback when they go stale can be tested.
 * Arguments: HEADING_DEG ALTITUDE_FT AIRSPEED_KT SILENT_AFTER_S [CONTINGENCY]. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ARINC653.h"
#include "rpas/ports.h"

static SAMPLING_PORT_ID_TYPE out;
static rpas_mission_msg_t target;
static int64_t silent_after_ns;

static void feed(void)
{
    for (;;) {
        RETURN_CODE_TYPE rc;
        SYSTEM_TIME_TYPE now;
        GET_TIME(&now, &rc);
        if ((int64_t)now < silent_after_ns) {
            target.t_ns = (int64_t)now;
            WRITE_SAMPLING_MESSAGE(out, (MESSAGE_ADDR_TYPE)&target, sizeof target, &rc);
        }
        PERIODIC_WAIT(&rc);
    }
}

int main(int argc, char **argv)
{
    RETURN_CODE_TYPE rc;
    if (argc < 5) {
        static const char msg[] = "mission_feed: wants HEADING ALTITUDE AIRSPEED SILENT_AFTER_S";
        RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE)msg, sizeof msg - 1, &rc);
        return 1;
    }
    target.mode = argc > 5 && strcmp(argv[5], "CONTINGENCY") == 0 ? RPAS_MODE_CONTINGENCY
                                                                 : RPAS_MODE_MISSION;
    target.lat_mode = RPAS_LAT_HDG;
    target.vert_mode = RPAS_VERT_ALT;
    target.hdg_deg = atof(argv[1]);
    target.alt_ft = atof(argv[2]);
    target.ias_kt = atof(argv[3]);
    silent_after_ns = (int64_t)(atof(argv[4]) * 1e9);
    CREATE_SAMPLING_PORT("MISSION_OUT", sizeof target, SOURCE, 500000000, &out, &rc);
    if (rc != NO_ERROR)
        return 1;
    PROCESS_ATTRIBUTE_TYPE a = {.PERIOD = 50000000, .TIME_CAPACITY = 50000000,
                                .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)feed, .STACK_SIZE = 65536,
                                .BASE_PRIORITY = 10, .DEADLINE = SOFT, .NAME = "feed"};
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&a, &pid, &rc);
    START(pid, &rc);
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
