/* SPDX-License-Identifier: Apache-2.0 */
/* The io partition's APEX main (the system partition, the only one with Linux I/O): creates
 * its ports and processes from the contract the build generated from the system model, reads
 * its settings from its arguments, and runs the core (io_core.h) between the CAN bus, the
 * node's DDS agent and the sampling ports.
 *
 * Process `rx` (every major frame, at its start) decodes the frames the bus delivered; in a
 * redundant system it also updates the membership, runs the self-monitor and exchanges its
 * inputs with the other nodes through the DDS agent, then writes the (agreed) samples to the
 * ports. Process `tx` (after nav_fcs's window) encodes nav_fcs's outputs onto CAN with this
 * node's redundancy channel and sends telemetry to DDS. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "ARINC653.h"
#include "canbus/client.h"
#include "io_core.h"
#include "io_ports.h"
#include "rpas/port.h"
#include "rpas/process.h"
#include "rpas/report.h"
#include "xch/client.h"

/* The partition's state: one instance, owned here; the core takes it by pointer. */
static struct {
    io_settings_t cfg;
    io_rx_t rx;
    io_red_t red;
    canbus_client_t bus;
    bool bus_up, bus_told;
    xch_client_t xch;
    bool xch_on, xch_up, xch_told;
    uint32_t frame_no;      /* major frame of the current rx */
    uint32_t tx_frame;      /* tx cycles so far */
    uint32_t last_fcs_mode; /* for the node's health on DDS */
    io_fault_state_t faults; /* its --fault arguments, in their spells */
    io_fault_reports_t fault_reports;
    long port[IO_PORT_COUNT]; /* SAMPLING_PORT_ID_TYPE or QUEUING_PORT_ID_TYPE, by the port */
} io;

static int64_t now_ns(void)
{
    SYSTEM_TIME_TYPE t = 0;
    RETURN_CODE_TYPE rc;
    GET_TIME(&t, &rc);
    return (int64_t)t;
}

static void raise_error(const char *msg)
{
    RETURN_CODE_TYPE rc;
    RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE)msg,
                            (ERROR_MESSAGE_SIZE_TYPE)strlen(msg), &rc);
}

/* Connects once; a bus that is not there is reported (the HM table says what follows) and
 * tried again at io's next window; the flight goes on without this node's I/O meanwhile. */
static bool ensure_bus(void)
{
    if (io.bus_up)
        return true;
    char name[IO_NAME_MAX + 3], err[256];
    snprintf(name, sizeof name, "%s/io", io.cfg.node);
    int rc = canbus_client_connect(&io.bus, io.cfg.canbus, name, CANBUS_ROLE_CAN, io.cfg.channel + 1,
                                   err, sizeof err);
    if (rc != CANBUS_OK) {
        rpas_report("io: %s", err);
        raise_error("io: CAN bus unreachable");
        return false;
    }
    io.bus_up = true;
    return true;
}

static void bus_down(const char *what, int rc)
{
    rpas_report("io: CAN bus %s failed: %s", what, strerror(-rc));
    canbus_client_close(&io.bus);
    io.bus_up = false;
}

static void xch_down(void)
{
    xch_client_close(&io.xch);
    io.xch_up = false;
    io.red.health_sent = false; /* a new agent hears the node's health at once */
}

static void xch_send(uint16_t type, int64_t t, const void *p, size_t len)
{
    if (io.xch_up && xch_client_send(&io.xch, type, io.frame_no, t, p, len) != 0)
        xch_down();
}

static void write_port(int p, const void *msg, size_t len)
{
    RETURN_CODE_TYPE rc;
    WRITE_SAMPLING_MESSAGE((SAMPLING_PORT_ID_TYPE)io.port[p], (MESSAGE_ADDR_TYPE)msg,
                           (MESSAGE_SIZE_TYPE)len, &rc);
}

/* Reads a sampling port; true if a valid message of the port's size is there. */
static bool read_port(int p, void *msg)
{
    MESSAGE_SIZE_TYPE n = 0;
    VALIDITY_TYPE valid = INVALID;
    RETURN_CODE_TYPE rc;
    READ_SAMPLING_MESSAGE((SAMPLING_PORT_ID_TYPE)io.port[p], (MESSAGE_ADDR_TYPE)msg, &n, &valid,
                          &rc);
    return rc == NO_ERROR && valid == VALID && n == io_port_spec[p].size;
}

/* The membership and the self-monitor over the frame that ended (a redundant system only). */
static void watch_replicas(void)
{
    uint32_t before = io.red.members;
    uint32_t lost = io_membership_update(&io.red);
    if (lost) {
        char now[64], gone[64];
        io_node_list(io.red.members, io.red.n_nodes, now, sizeof now);
        io_node_list(before & ~io.red.members, io.red.n_nodes, gone, sizeof gone);
        rpas_report("membership %s (lost %s)", now, gone);
    }
    io_monitor_t m;
    io_self_monitor(&io.red, &m);
    for (unsigned k = 0; k < io.red.n_nodes; k++) {
        if (!(m.newly_failed & (1u << k)))
            continue;
        if (k == io.red.channel) {
            rpas_report("cross-channel monitor: own output voted out (%s)", m.reason[k]);
            raise_error("cross-channel disagreement: own output voted out");
        } else {
            rpas_report("cross-channel monitor: node%u voted out (%s)", k + 1, m.reason[k]);
        }
    }
    if (m.disagree)
        rpas_report("cross-channel monitor: two replicas left and they disagree");
}

/* A node whose samples the agreement refused for their time stamps: said once per node. */
static void report_refused_stamps(void)
{
    static uint32_t told;
    uint32_t fresh = io.red.refused_new & ~told;
    io.red.refused_new = 0;
    for (unsigned k = 0; k < io.red.n_nodes; k++)
        if (fresh & (1u << k))
            rpas_report("cross-channel agreement: node%u's samples stamped outside the frame or "
                        "older than their refresh period: left out",
                        k + 1);
    told |= fresh;
}

/* The cross-channel exchange of this frame's inputs, and this node's health. */
static void exchange_inputs(int64_t t)
{
    if (!io.xch_up) {
        char err[256];
        if (xch_client_connect(&io.xch, io.cfg.dds, io.cfg.channel + 1, err, sizeof err) != 0) {
            if (!io.xch_told)
                rpas_report("io: DDS agent: %s", err);
            io.xch_told = true;
            return;
        }
        io.xch_up = true;
    }
    struct xch_inputs mine;
    io_inputs(&io.rx, &mine);
    mine.wait_mask = io.red.members;
    mine.plan_crc = io.rx.uplink.plan_crc;
    struct xch_agreed ag;
    int rc = xch_client_exchange(&io.xch, io.frame_no, t, &mine, &ag);
    if (rc != 0) {
        rpas_report("io: cross-channel exchange failed: %s", strerror(-rc));
        xch_down();
        return;
    }
    io_apply_agreed(&io.red, &io.rx, &ag, t);
    uint32_t plan = io_plan_agreement(&ag, io.red.members, io.red.plan_agreed);
    if (plan != io.red.plan_agreed)
        rpas_report("io: mission plan 0x%08x held by every member", (unsigned)plan);
    io.red.plan_agreed = plan;
    report_refused_stamps();
    struct xch_health h;
    io_health(&io.red, io.last_fcs_mode, &h);
    if (io_health_due(&io.red, &h, io.frame_no))
        xch_send(XCH_HEALTH, t, &h, sizeof h);
}

/* The mission plan: a plan that came whole goes to the mission manager (its CRC, its
 * length, the image); the plan agreement and the pilot's mission command, every frame. */
static void mission_uplink(int64_t t)
{
    io_uplink_t *u = &io.rx.uplink;
    static const char *const what[] = {
        [IO_UPLINK_STARTED] = "upload started", [IO_UPLINK_COMPLETE] = "received",
        [IO_UPLINK_BAD_CRC] = "refused: CRC mismatch, the plan held is kept",
        [IO_UPLINK_BAD_HEADER] = "refused: bad length"};
    if (io.rx.uplink_event != IO_UPLINK_NONE)
        rpas_report("io: mission plan 0x%08x (%u bytes) %s (%llu refused so far)",
                    (unsigned)u->crc, (unsigned)u->len, what[io.rx.uplink_event],
                    (unsigned long long)u->refused);
    if (u->plan_new) {
        static uint8_t msg[8 + RPAS_PLAN_MAX_BYTES];
        memcpy(msg, &u->plan_crc, 4);
        memcpy(msg + 4, &u->plan_len, 4);
        memcpy(msg + 8, u->plan, u->plan_len);
        RETURN_CODE_TYPE rc;
        SEND_QUEUING_MESSAGE((QUEUING_PORT_ID_TYPE)io.port[IO_PORT_PLAN_OUT], (MESSAGE_ADDR_TYPE)msg,
                             (MESSAGE_SIZE_TYPE)(8 + u->plan_len), 0, &rc);
        u->plan_new = false;
        if (!io.xch_on) /* one node: the plan it holds is the system's */
            io.red.plan_agreed = u->plan_crc;
    }
    rpas_mm_cmd_msg_t c = io.rx.mm_cmd;
    c.t_ns = t;
    c.plan_crc = io.red.plan_agreed;
    write_port(IO_PORT_MM_CMD_OUT, &c, sizeof c);
}

/* Writes the samples that came (or were agreed) this frame to their ports. */
static void write_samples(int64_t t)
{
    io_rx_t *rx = &io.rx;
    if (rx->gps_new)
        write_port(IO_PORT_GPS_OUT, &rx->gps, sizeof rx->gps);
    if (rx->ahrs_new)
        write_port(IO_PORT_AHRS_OUT, &rx->ahrs, sizeof rx->ahrs);
    if (rx->air_new)
        write_port(IO_PORT_AIR_OUT, &rx->air, sizeof rx->air);
    if (rx->pilot_new) {
        write_port(IO_PORT_PILOT_OUT, &rx->pilot, sizeof rx->pilot);
        struct xch_mission m;
        if (io_mission_due(&io.red, &rx->pilot, io.frame_no, &m))
            xch_send(XCH_MISSION, t, &m, sizeof m);
    }
    if (rx->act_new)
        write_port(IO_PORT_ACT_OUT, &rx->act, sizeof rx->act);
    if (rx->traffic_new)
        write_port(IO_PORT_TRAFFIC_OUT, &rx->traffic, sizeof rx->traffic);
    if (rx->radalt_new)
        write_port(IO_PORT_RADALT_OUT, &rx->radalt, sizeof rx->radalt);
    mission_uplink(t);
    io_rx_written(rx);
}

static void rx_process(void)
{
    for (;;) {
        int64_t t = now_ns();
        io.frame_no = (uint32_t)(t / IO_PARTITION_PERIOD_NS);
        if (ensure_bus()) {
            struct canbus_rec r;
            int got;
            while ((got = canbus_client_recv(&io.bus, &r)) == 1)
                if (r.type == CANBUS_MSG_FRAME)
                    io_rx_frame(&io.rx, &io.red.peers, io.red.n_nodes, &r);
            if (got < 0 && got != -ESHUTDOWN)
                bus_down("receive", got);
            if (io.red.n_nodes > 1)
                watch_replicas();
            if (io.xch_on)
                exchange_inputs(t);
            write_samples(t);
        }
        RETURN_CODE_TYPE rc;
        PERIODIC_WAIT(&rc);
    }
}

static void tx_process(void)
{
    for (;;) {
        if (ensure_bus()) {
            int64_t t = now_ns();
            io_outputs_t o;
            o.have_cmd = read_port(IO_PORT_ACT_CMD_IN, &o.cmd);
            o.have_status = read_port(IO_PORT_FCS_STATUS_IN, &o.status);
            o.have_nav = read_port(IO_PORT_NAV_IN, &o.nav);
            o.have_mm = read_port(IO_PORT_MM_STATUS_IN, &o.mm);
            io_cmd_faults(&io.cfg, &io.faults, t, o.have_cmd ? &o.cmd : NULL, &io.fault_reports);
            for (unsigned i = 0; i < io.fault_reports.n; i++)
                rpas_report("%s", io.fault_reports.line[i]);
            if (o.have_status)
                io.last_fcs_mode = o.status.mode;
            io_frame_t f[IO_TX_MAX_FRAMES];
            int n = io_tx_frames(&o, io.red.channel, io.tx_frame, f, io.red.own_cmd.v);
            io.red.own_cmd.have = o.have_cmd;
            for (int i = 0; i < n; i++)
                if (f[i].len != 8 || canbus_client_send(&io.bus, f[i].id, true, f[i].data, 8, t) != 0)
                    io.rx.decode_errors++;
            if (io.xch_up && o.have_nav && o.have_status) {
                struct xch_telemetry tm;
                io_telemetry(&o, &tm);
                xch_send(XCH_TELEMETRY, t, &tm, sizeof tm);
            }
            int rc = canbus_client_flush(&io.bus);
            if (rc != 0)
                bus_down("send", rc);
        }
        io.tx_frame++;
        RETURN_CODE_TYPE rc;
        PERIODIC_WAIT(&rc);
    }
}

/* A failed initialisation: reported, and the partition idles (what the standard's
 * SET_PARTITION_MODE(IDLE) gives: it stays down until the module restarts it). */
static int fail(const char *what, RETURN_CODE_TYPE rc)
{
    rpas_report("io: init failed: %s (rc=%d)", what, (int)rc);
    fprintf(stderr, "io: %s failed: return code %d\n", what, (int)rc);
    SET_PARTITION_MODE(IDLE, &rc);
    return 1;
}

int main(int argc, char *argv[])
{
    char err[200];
    if (io_settings_parse(&io.cfg, argc, argv, err, sizeof err) != 0) {
        rpas_report("io: %s", err);
        fprintf(stderr, "io: %s\n", err);
        return fail("arguments", INVALID_CONFIG);
    }
    io_rx_init(&io.rx);
    if (io_red_init(&io.red, &io.cfg) != 0)
        return fail("voting settings", INVALID_CONFIG);
    /* The agreement's time bounds: the frame, and the refresh period of each sample's port. */
    io.red.frame_ns = IO_PARTITION_PERIOD_NS;
    io.red.max_age_ns[0] = io_port_spec[IO_PORT_GPS_OUT].refresh_ns;
    io.red.max_age_ns[1] = io_port_spec[IO_PORT_AHRS_OUT].refresh_ns;
    io.red.max_age_ns[2] = io_port_spec[IO_PORT_AIR_OUT].refresh_ns;
    io.xch_on = io.cfg.n_nodes > 1;
    io_faults_init(&io.faults);
    for (unsigned k = 0; k < io.cfg.n_faults; k++) {
        char what[80];
        fi_wo_describe(&io.cfg.fault[k], what, sizeof what);
        rpas_report("io: armed fault %s (wrong_output %s, %s from %g s)", io.cfg.fault[k].spec.fid,
                    what, fi_duration_name(io.cfg.fault[k].spec.duration),
                    (double)io.cfg.fault[k].spec.at_ns / 1e9);
    }
    RETURN_CODE_TYPE rc;
    const char *bad_port = rpas_create_ports(io_port_spec, IO_PORT_COUNT, io.port, &rc);
    if (bad_port)
        return fail(bad_port, rc);
    void (*entry[IO_PROCESS_COUNT])(void) = {[IO_PROCESS_RX] = rx_process, [IO_PROCESS_TX] = tx_process};
    for (int i = 0; i < IO_PROCESS_COUNT; i++) {
        PROCESS_ID_TYPE pid;
        rpas_start_process(&io_process_spec[i], entry[i], &pid, &rc);
        if (rc != NO_ERROR)
            return fail(io_process_spec[i].name, rc);
    }
    SET_PARTITION_MODE(NORMAL, &rc);
    return fail("SET_PARTITION_MODE NORMAL", rc);
}
