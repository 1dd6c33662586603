/* SPDX-License-Identifier: Apache-2.0 */
/* CRC-32 (IEEE 802.3, reflected, as zlib's crc32), a byte at a time through a table: the
 * mission uplink's check (mission_plan.h) and the flight data recorder's records. */
#ifndef RPAS_CRC32_H
#define RPAS_CRC32_H

#include <stddef.h>
#include <stdint.h>

/* The reflected polynomial's table, built at the first use (each program has its own). */
static inline const uint32_t *rpas_crc32_table(void)
{
    static uint32_t table[256];
    static int ready;
    if (!ready) {
        for (uint32_t i = 0; i < 256; i++) {
            uint32_t c = i;
            for (int k = 0; k < 8; k++)
                c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
            table[i] = c;
        }
        ready = 1;
    }
    return table;
}

static inline uint32_t rpas_crc32(const void *data, size_t len)
{
    const uint32_t *t = rpas_crc32_table();
    const uint8_t *p = (const uint8_t *)data;
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < len; i++)
        crc = (crc >> 8) ^ t[(crc ^ p[i]) & 0xFFu];
    return ~crc;
}

#endif
