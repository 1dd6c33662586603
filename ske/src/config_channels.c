/* SPDX-License-Identifier: Apache-2.0 */
/* The channels of the module XML (Connection_Table): each connects a source port to its
 * destinations, of one kind and one message size. */
#include "ske__config.h"

#include <string.h>

static bool load_endpoint(ske_loader_t *L, const xmlNode *ep, ske_endpoint_t *out)
{
    for (const xmlNode *c = ep->children; c; c = c->next) {
        if (!ske__is_elem(c, "Standard_Partition", false))
            continue;
        int pi = ske__partition_ref(L, c);
        if (pi < 0)
            return false;
        char port[SKE_NAME_MAX];
        if (!ske__attr_name(L, c, "PortName", port))
            return false;
        int po = ske_config_port_by_name(&L->m->partitions[pi], port);
        if (po < 0) {
            ske__fail(L, c, "a channel connects ports that partitions declare",
                      "partition '%s' declares no port named '%s'", L->m->partitions[pi].name,
                      port);
            return false;
        }
        out->partition = pi;
        out->port = po;
        return true;
    }
    ske__fail(L, ep, "a channel end names a Standard_Partition", "missing Standard_Partition");
    return false;
}

static ske_port_cfg_t *port_of(ske_module_cfg_t *m, ske_endpoint_t e)
{
    return &m->partitions[e.partition].ports[e.port];
}

static const char *kind_name(ske_port_kind_t k)
{
    return k == SKE_PORT_SAMPLING ? "sampling" : "queuing";
}

void ske__load_channel(ske_loader_t *L, const xmlNode *n)
{
    ske_module_cfg_t *m = L->m;
    if (m->n_channels >= SKE_MAX_CHANNELS) {
        ske__fail(L, n, "at most 256 channels", "too many channels");
        return;
    }
    ske_channel_cfg_t *ch = &m->channels[m->n_channels];
    memset(ch, 0, sizeof *ch);
    ch->line = ske__line_of(L, n);
    uint64_t id;
    if (!ske__attr_u64(L, n, "ChannelIdentifier", &id, INT32_MAX, true) ||
        !ske__attr_name(L, n, "ChannelName", ch->name))
        return;
    ch->id = (int32_t)id;
    for (int i = 0; i < m->n_channels; i++)
        if (m->channels[i].id == ch->id) {
            ske__fail(L, n, "channel identifiers are unique",
                      "ChannelIdentifier=%d is already used (line %d)", ch->id,
                      m->channels[i].line);
            return;
        }
    const xmlNode *src_node = NULL;
    const xmlNode *dst_node[SKE_MAX_DESTINATIONS] = {NULL};
    for (const xmlNode *c = n->children; c && !L->failed; c = c->next) {
        if (ske__is_elem(c, "Source", false)) {
            src_node = c;
            if (!load_endpoint(L, c, &ch->src))
                return;
        } else if (ske__is_elem(c, "Destination", false)) {
            if (ch->n_dst >= SKE_MAX_DESTINATIONS) {
                ske__fail(L, c, "at most 16 destinations per channel", "too many destinations");
                return;
            }
            if (!load_endpoint(L, c, &ch->dst[ch->n_dst]))
                return;
            dst_node[ch->n_dst++] = c;
        }
    }
    if (!src_node || ch->n_dst == 0) {
        ske__fail(L, n, "a channel has one Source and at least one Destination",
                  "channel '%s' lacks a %s", ch->name, src_node ? "Destination" : "Source");
        return;
    }
    ske_port_cfg_t *sp = port_of(m, ch->src);
    ch->kind = sp->kind;
    if (sp->dir != SKE_DIR_SOURCE) {
        ske__fail(L, src_node, "a channel's Source is a SOURCE port",
                  "port '%s' of partition '%s' is a DESTINATION port, it cannot be the source of "
                  "channel '%s'", sp->name, m->partitions[ch->src.partition].name, ch->name);
        return;
    }
    if (sp->channel >= 0) {
        ske__fail(L, src_node, "a port belongs to one channel",
                  "port '%s' of partition '%s' is already the source of channel '%s'", sp->name,
                  m->partitions[ch->src.partition].name, m->channels[sp->channel].name);
        return;
    }
    if (ch->kind == SKE_PORT_QUEUING && ch->n_dst > 1) {
        ske__fail(L, n, "a queuing channel has exactly one destination",
                  "queuing channel '%s' has %d destinations", ch->name, ch->n_dst);
        return;
    }
    sp->channel = m->n_channels;
    for (int d = 0; d < ch->n_dst; d++) {
        ske_port_cfg_t *dp = port_of(m, ch->dst[d]);
        const char *pname = m->partitions[ch->dst[d].partition].name;
        if (dp->kind != ch->kind) {
            ske__fail(L, dst_node[d], "a channel connects ports of one kind",
                      "channel '%s' connects %s port '%s' to %s port '%s' of partition '%s'",
                      ch->name, kind_name(sp->kind), sp->name, kind_name(dp->kind), dp->name,
                      pname);
            return;
        }
        if (dp->dir != SKE_DIR_DESTINATION) {
            ske__fail(L, dst_node[d], "a channel's Destination is a DESTINATION port",
                      "port '%s' of partition '%s' is a SOURCE port, it cannot be a destination of "
                      "channel '%s'", dp->name, pname, ch->name);
            return;
        }
        if (dp->max_size != sp->max_size) {
            ske__fail(L, dst_node[d], "the ports of a channel have the same MaxMessageSize",
                      "channel '%s': source port '%s' has MaxMessageSize=%u but destination port "
                      "'%s' of partition '%s' has %u", ch->name, sp->name, sp->max_size, dp->name,
                      pname, dp->max_size);
            return;
        }
        if (dp->channel >= 0) {
            ske__fail(L, dst_node[d], "a port belongs to one channel",
                      "port '%s' of partition '%s' is already a destination of channel '%s'",
                      dp->name, pname, m->channels[dp->channel].name);
            return;
        }
        dp->channel = m->n_channels;
    }
    m->n_channels++;
}
