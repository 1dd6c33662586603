/* SPDX-License-Identifier: Apache-2.0 */
/* Port memory: one sealed memory object per port (a sampling channel's destinations map
 * their source's read-only), set up before any partition starts, freed at the end. */
#include "ske__supervisor.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

int ske__memobj(const char *name, size_t size, void **mem)
{
    int fd = memfd_create(name, MFD_CLOEXEC | MFD_ALLOW_SEALING);
    if (fd < 0)
        return -errno;
    /* Sealed at its size: a partition holding a descriptor cannot shrink it under the SKE's
     * mapping (the SKE would die of SIGBUS on its next access). */
    /* Read-only for its owner: a descriptor handed out read-write stays so, but nobody
     * without capabilities (every partition) can open it anew for writing, e.g. a read-only
     * destination descriptor through /proc/self/fd before the APEX library closes it. */
    if (ftruncate(fd, (off_t)size) != 0 ||
        fcntl(fd, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL) != 0 ||
        fchmod(fd, 0400) != 0) {
        int e = errno;
        close(fd);
        return -e;
    }
    void *p = mmap(NULL, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) {
        int e = errno;
        close(fd);
        return -e;
    }
    *mem = p;
    return fd;
}

/* A second descriptor of the same memory opened read-only: a mapping made through it can
 * never become writable, not even with mprotect(). */
static int reopen_ro(int fd)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    return open(path, O_RDONLY | O_CLOEXEC);
}

int ske__setup_ports(ske_t *s, char *err, size_t errlen)
{
    const ske_module_cfg_t *m = s->cfg;
    /* Sampling channels first: the source's memory object is shared by its destinations. */
    for (int pi = 0; pi < m->n_partitions; pi++) {
        ske_part_t *p = &s->parts[pi];
        for (int k = 0; k < p->cfg->n_ports; k++) {
            const ske_port_cfg_t *pc = &p->cfg->ports[k];
            ske_portmem_t *pm = &p->ports[k];
            pm->fd = pm->fd_ro = -1;
            if (pc->kind == SKE_PORT_SAMPLING && pc->dir == SKE_DIR_DESTINATION && pc->channel >= 0)
                continue; /* filled from the source below */
            char name[80];
            snprintf(name, sizeof name, "ima-%s-%s", p->cfg->name, pc->name);
            pm->size = pc->kind == SKE_PORT_SAMPLING ? ske_sampling_map_size(pc->max_size)
                                                     : ske_queue_map_size(pc->max_size, pc->max_nb);
            pm->fd = ske__memobj(name, pm->size, &pm->mem);
            if (pm->fd < 0) {
                snprintf(err, errlen, "port memory for %s.%s: %s", p->cfg->name, pc->name,
                         strerror(-pm->fd));
                return SKE_E_SYS;
            }
            if (pc->kind == SKE_PORT_SAMPLING)
                ske_sampling_init(pm->mem, pc->max_size);
            else
                ske_queue_init(pm->mem, pc->max_size, pc->max_nb);
            if (pc->dir == SKE_DIR_DESTINATION) {
                pm->fd_ro = reopen_ro(pm->fd);
                if (pm->fd_ro < 0) {
                    snprintf(err, errlen, "read-only port descriptor: %s", strerror(errno));
                    return SKE_E_SYS;
                }
            }
        }
    }
    for (int c = 0; c < m->n_channels; c++) {
        const ske_channel_cfg_t *ch = &m->channels[c];
        if (ch->kind != SKE_PORT_SAMPLING)
            continue;
        const ske_portmem_t *src = &s->parts[ch->src.partition].ports[ch->src.port];
        for (int d = 0; d < ch->n_dst; d++) {
            ske_portmem_t *pm = &s->parts[ch->dst[d].partition].ports[ch->dst[d].port];
            pm->mem = src->mem;
            pm->size = src->size;
            pm->fd = -1;
            pm->fd_ro = reopen_ro(src->fd);
            if (pm->fd_ro < 0) {
                snprintf(err, errlen, "read-only port descriptor: %s", strerror(errno));
                return SKE_E_SYS;
            }
        }
    }
    return SKE_OK;
}

void ske__free_ports(ske_part_t *p)
{
    for (int k = 0; k < p->cfg->n_ports; k++) {
        ske_portmem_t *pm = &p->ports[k];
        if (pm->fd >= 0) {
            munmap(pm->mem, pm->size);
            close(pm->fd);
        }
        if (pm->fd_ro >= 0)
            close(pm->fd_ro);
    }
}
