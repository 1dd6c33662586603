/* SPDX-License-Identifier: Apache-2.0 */
/* The whole ARINC 653 APEX C binding provided by the IMA Testbed: include this one. Every header
 * it includes declares its services extern "C", so C++ partitions include it as C ones do. */
#ifndef ARINC653_H
#define ARINC653_H

#include "apex_types.h"
#include "apex_time.h"
#include "apex_process.h"
#include "apex_partition.h"
#include "apex_sampling.h"
#include "apex_sampling_ext.h"
#include "apex_queuing.h"
#include "apex_buffer.h"
#include "apex_blackboard.h"
#include "apex_semaphore.h"
#include "apex_event.h"
#include "apex_error.h"
#include "apex_schedule.h"

#endif /* ARINC653_H */
