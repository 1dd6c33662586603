/* SPDX-License-Identifier: Apache-2.0 */
/* Test partition standing in for the mission manager: writes MISSION targets on MISSION_OUT
 * every major frame until a given time, then falls silent, so that the flight-control
 * partition's use of mission targets and its fallback when they go stale can be tested.
 * Arguments: HEADING_DEG ALTITUDE_FT AIRSPEED_KT SILENT_AFTER_S [CONTINGENCY].
 * When its module gives it the queuing ports FEED_LOG_OUT and FEED_LOG_IN (a channel from
 * itself to itself, as campaigns' mission systems do), it also logs each target it sent there
 * and reads the log back: a queuing channel a fault can flood. */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ARINC653.h"
#include "rpas/ports.h"

static SAMPLING_PORT_ID_TYPE out;
static rpas_mission_msg_t target;
static int64_t silent_after_ns;
static QUEUING_PORT_ID_TYPE log_out, log_in;
static bool logging;

/* The log channel: one message per target sent, read back in the same period. */
static void log_target(void)
{
    RETURN_CODE_TYPE rc;
    SEND_QUEUING_MESSAGE(log_out, (MESSAGE_ADDR_TYPE)&target.t_ns, sizeof target.t_ns, 0, &rc);
    int64_t t;
    MESSAGE_SIZE_TYPE len;
    do
        RECEIVE_QUEUING_MESSAGE(log_in, 0, (MESSAGE_ADDR_TYPE)&t, &len, &rc);
    while (rc == NO_ERROR || rc == INVALID_CONFIG); /* INVALID_CONFIG: a message after a loss */
}

static void feed(void)
{
    for (;;) {
        RETURN_CODE_TYPE rc;
        SYSTEM_TIME_TYPE now;
        GET_TIME(&now, &rc);
        if ((int64_t)now < silent_after_ns) {
            target.t_ns = (int64_t)now;
            WRITE_SAMPLING_MESSAGE(out, (MESSAGE_ADDR_TYPE)&target, sizeof target, &rc);
            if (logging)
                log_target();
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
    RETURN_CODE_TYPE rc_out, rc_in;
    CREATE_QUEUING_PORT("FEED_LOG_OUT", 8, 8, SOURCE, FIFO, &log_out, &rc_out);
    CREATE_QUEUING_PORT("FEED_LOG_IN", 8, 8, DESTINATION, FIFO, &log_in, &rc_in);
    logging = rc_out == NO_ERROR && rc_in == NO_ERROR; /* INVALID_CONFIG: not in this module */
    PROCESS_ATTRIBUTE_TYPE a = {.PERIOD = 50000000, .TIME_CAPACITY = 50000000,
                                .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)feed, .STACK_SIZE = 65536,
                                .BASE_PRIORITY = 10, .DEADLINE = SOFT, .NAME = "feed"};
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&a, &pid, &rc);
    START(pid, &rc);
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
