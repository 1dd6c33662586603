/* SPDX-License-Identifier: Apache-2.0 */
/* ARINC 653 Part 1 APEX global types and constants, C binding. */
#ifndef APEX_TYPES
#define APEX_TYPES

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Domain limits (implementation dependent). */
#define SYSTEM_LIMIT_NUMBER_OF_PARTITIONS 32 /* module scope */
#define SYSTEM_LIMIT_NUMBER_OF_MESSAGES 1048576 /* module scope */
#define SYSTEM_LIMIT_MESSAGE_SIZE 1048576 /* module scope */
#define SYSTEM_LIMIT_NUMBER_OF_PROCESSES 128 /* partition scope */
#define SYSTEM_LIMIT_NUMBER_OF_SAMPLING_PORTS 64 /* partition scope */
#define SYSTEM_LIMIT_NUMBER_OF_QUEUING_PORTS 64 /* partition scope */
#define SYSTEM_LIMIT_NUMBER_OF_BUFFERS 256 /* partition scope */
#define SYSTEM_LIMIT_NUMBER_OF_BLACKBOARDS 256 /* partition scope */
#define SYSTEM_LIMIT_NUMBER_OF_SEMAPHORES 256 /* partition scope */
#define SYSTEM_LIMIT_NUMBER_OF_EVENTS 256 /* partition scope */

/* Base APEX types: 8-bit unsigned, 32-bit signed, 32-bit unsigned, 64-bit signed. The 64-bit one
 * is long long, as the standard's C binding declares it (not int64_t, which is long on 64-bit
 * Linux): applications written for other APEX implementations print times with %lld and keep
 * them in long long variables. */
typedef uint8_t APEX_BYTE;
typedef int32_t APEX_INTEGER;
typedef uint32_t APEX_UNSIGNED;
typedef long long APEX_LONG_INTEGER;

typedef enum {
    NO_ERROR = 0, /* request valid and operation performed */
    NO_ACTION = 1, /* status of system unaffected by request */
    NOT_AVAILABLE = 2, /* resource required by request unavailable */
    INVALID_PARAM = 3, /* invalid parameter specified in request */
    INVALID_CONFIG = 4, /* parameter incompatible with configuration */
    INVALID_MODE = 5, /* request incompatible with current mode */
    TIMED_OUT = 6 /* time-out tied up with request has expired */
} RETURN_CODE_TYPE;

#define MAX_NAME_LENGTH 30
typedef char NAME_TYPE[MAX_NAME_LENGTH];
typedef void (*SYSTEM_ADDRESS_TYPE);
typedef APEX_BYTE *MESSAGE_ADDR_TYPE;
typedef APEX_INTEGER MESSAGE_SIZE_TYPE;
typedef APEX_INTEGER MESSAGE_RANGE_TYPE;

typedef enum { SOURCE = 0, DESTINATION = 1 } PORT_DIRECTION_TYPE;
typedef enum { FIFO = 0, PRIORITY = 1 } QUEUING_DISCIPLINE_TYPE;

/* Nanoseconds. */
typedef APEX_LONG_INTEGER SYSTEM_TIME_TYPE;
#define INFINITE_TIME_VALUE ((SYSTEM_TIME_TYPE)-1)
#define INFINITE_SYSTEM_TIME_VALUE INFINITE_TIME_VALUE /* the older binding's name */

#ifdef __cplusplus
}
#endif

#endif /* APEX_TYPES */
