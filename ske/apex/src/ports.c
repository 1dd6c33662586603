/* SPDX-License-Identifier: Apache-2.0 */
/* Port look-up and mapping shared by the sampling and queuing services. A partition maps
 * only the descriptors the SKE gave it, destination ports read-only. */
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "apex__rt.h"

int apex__port_by_name(const char *name, uint32_t kind)
{
    const ske_ctl_t *c = apex__rt.ctl;
    size_t n = strnlen(name, MAX_NAME_LENGTH);
    for (uint32_t k = 0; k < c->n_ports && k < SKE_MAX_PORTS; k++) {
        const ske_port_desc_t *d = &c->ports[k];
        if (d->kind == kind && strnlen(d->name, SKE_NAME_MAX) == n && memcmp(d->name, name, n) == 0)
            return (int)k;
    }
    return -1;
}

int apex__port_index(APEX_INTEGER id, uint32_t kind)
{
    const ske_ctl_t *c = apex__rt.ctl;
    if (id < 1 || (uint32_t)id > c->n_ports || id > SKE_MAX_PORTS)
        return -1;
    int k = id - 1;
    if (c->ports[k].kind != kind || !apex__rt.ports[k].created)
        return -1;
    return k;
}

/* Maps every port the SKE gave the partition and closes the descriptors, before main()
 * runs: the partition then holds no descriptor it could reopen with other rights
 * (/proc/self/fd), and CREATE_*_PORT only checks the configuration. */
void apex__ports_attach(void)
{
    ske_ctl_t *c = apex__rt.ctl;
    for (uint32_t k = 0; k < c->n_ports && k < SKE_MAX_PORTS; k++) {
        const ske_port_desc_t *d = &c->ports[k];
        int prot = d->dir == SKE_DIR_SOURCE ? PROT_READ | PROT_WRITE : PROT_READ;
        void *m = mmap(NULL, d->map_size, prot, MAP_SHARED, d->fd, 0);
        if (m != MAP_FAILED) {
            apex__rt.ports[k].mem = m;
            apex__rt.ports[k].map_size = d->map_size;
        }
        close(d->fd);
    }
}

bool apex__port_map(int k)
{
    if (!apex__rt.ports[k].mem)
        return false; /* the SKE's descriptor could not be mapped */
    apex__rt.ports[k].created = true;
    return true;
}
