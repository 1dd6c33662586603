/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the SKE's fault support: --fault specs checked against a module, test switches,
 * the FNV-1a hash of the port hashes, the in-place view of a sampling port's latest message. */
#include <stdlib.h>
#include <string.h>

#include "ske/config.h"
#include "ske__supervisor.h"
#include "ske_test.h"

static ske_module_cfg_t *load_example(void)
{
    ske_load_opts_t opts = {.schema_dir = IMA_SOURCE_DIR "/config/schema", .resolve_executables = false};
    ske_module_cfg_t *m = NULL;
    ske_diag_t d;
    if (ske_config_load(IMA_SOURCE_DIR "/config/examples/three_partitions.xml", &opts, &m, &d) != SKE_OK)
        return NULL;
    return m;
}

static void test_fnv1a64(void)
{
    /* The reference values of FNV-1a, 64 bits. */
    CHECK(ske_fnv1a64(SKE_FNV_OFFSET, "", 0) == 0xcbf29ce484222325ULL);
    CHECK(ske_fnv1a64(SKE_FNV_OFFSET, "a", 1) == 0xaf63dc4c8601ec8cULL);
    CHECK(ske_fnv1a64(SKE_FNV_OFFSET, "foobar", 6) == 0x85944171f73967e8ULL);
    /* Continued: the same as all at once. */
    CHECK(ske_fnv1a64(ske_fnv1a64(SKE_FNV_OFFSET, "foo", 3), "bar", 3) == 0x85944171f73967e8ULL);
}

static int parse(const ske_module_cfg_t *m, ske_faults_t *fs, const char *spec, char *err, size_t n)
{
    const char *specs[] = {spec};
    return ske__faults_parse(fs, m, specs, 1, err, n);
}

static void test_faults_against_the_module(void)
{
    ske_module_cfg_t *m = load_example();
    REQUIRE(m != NULL);
    ske_faults_t *fs = malloc(sizeof *fs);
    REQUIRE(fs != NULL);
    char err[512];
    CHECK_EQ(parse(m, fs, "deadline_miss:fid=d,at=1s,partition=consumer,process=sample", err, sizeof err), SKE_OK);
    CHECK_EQ(fs->f[0].cls, SKE_FAULT_DEADLINE_MISS);
    CHECK_STR(fs->f[0].target, "consumer.sample");
    CHECK_EQ(fs->f[0].done_spell, -1);
    CHECK_EQ(parse(m, fs, "stuck_output:fid=s,at=1s,partition=producer,port=SP_STATE", err, sizeof err), SKE_OK);
    CHECK_STR(fs->f[0].target, "producer.SP_STATE");
    CHECK_EQ(fs->f[0].port, 0);
    /* A CPU overrun spins past the partition's longest window (producer: 10 ms) by default. */
    CHECK_EQ(parse(m, fs, "cpu_overrun:fid=c,at=1s,partition=producer", err, sizeof err), SKE_OK);
    CHECK_EQ(fs->f[0].value_ns, 11000000);
    CHECK_EQ(parse(m, fs, "cpu_overrun:fid=c,at=1s,partition=producer,value=2.5", err, sizeof err), SKE_OK);
    CHECK_EQ(fs->f[0].value_ns, 2500000);
    CHECK_EQ(parse(m, fs, "cpu_overrun:fid=c,at=1s,partition=producer,value=3us", err, sizeof err), SKE_OK);
    CHECK_EQ(fs->f[0].value_ns, 3000);
    CHECK_EQ(parse(m, fs, "module_reset:fid=r,at=2s", err, sizeof err), SKE_OK);
    CHECK_EQ(fs->f[0].partition, -1);
    CHECK_STR(fs->f[0].target, "module");
    /* The foreign write's default port: the partition's first destination port. */
    CHECK_EQ(parse(m, fs, "foreign_port_write:fid=w,at=1s,partition=consumer", err, sizeof err), SKE_OK);
    CHECK_STR(fs->f[0].target, "consumer.SP_STATE_IN");
    CHECK_EQ(parse(m, fs, "corrupt_output:fid=x,at=1s,partition=consumer,port=SP_STATE_IN", err, sizeof err),
             SKE_E_CONFIG);
    CHECK(strstr(err, "needs a source sampling port") != NULL);
    CHECK_EQ(parse(m, fs, "numeric_error:fid=x,at=1s,partition=monitor,process=sample", err, sizeof err),
             SKE_E_CONFIG);
    CHECK(strstr(err, "its Process elements: watch") != NULL);
    /* Exhaustion up to the partition's limit (monitor: 32 MiB); none without a limit. */
    CHECK_EQ(parse(m, fs, "memory_exhaustion:fid=x,at=1s,partition=monitor", err, sizeof err), SKE_OK);
    CHECK_EQ(fs->f[0].value_ns, 0x2000000);
    m->partitions[2].memory_bytes = 0;
    CHECK_EQ(parse(m, fs, "memory_exhaustion:fid=x,at=1s,partition=monitor", err, sizeof err), SKE_E_CONFIG);
    CHECK(strstr(err, "no memory limit") != NULL);
    /* Slots in the order given, per partition. */
    const char *two[] = {"numeric_error:fid=a,at=1s,partition=monitor",
                         "numeric_error:fid=b,at=1s,partition=producer",
                         "stack_overflow:fid=c,at=2s,partition=monitor"};
    CHECK_EQ(ske__faults_parse(fs, m, two, 3, err, sizeof err), SKE_OK);
    CHECK_EQ(fs->f[0].slot, 0);
    CHECK_EQ(fs->f[1].slot, 0);
    CHECK_EQ(fs->f[2].slot, 1);
    free(fs);
    ske_config_free(m);
}

static void test_switches(void)
{
    ske_module_cfg_t *m = load_example();
    REQUIRE(m != NULL);
    ske_switches_t sw;
    char err[512];
    const char *ok[] = {"overrun-eats-next-window", "hm-action=consumer:COLD_START",
                        "corrupt-port=producer.SP_STATE@1.5s"};
    CHECK_EQ(ske__switches_parse(&sw, m, ok, 3, err, sizeof err), SKE_OK);
    CHECK(sw.eat_next_window);
    CHECK_EQ(sw.hm_action[1], HM_ACT_COLD_START);
    CHECK_EQ(sw.hm_action[0], -1);
    CHECK_EQ(sw.n_corrupt, 1);
    CHECK_EQ(sw.corrupt[0].t_ns, 1500000000);
    const char *bad[] = {"hm-action=consumer:SHUTDOWN"};
    CHECK_EQ(ske__switches_parse(&sw, m, bad, 1, err, sizeof err), SKE_E_CONFIG);
    ske_config_free(m);
}

static void test_latest_message_in_place(void)
{
    static _Alignas(8) uint8_t mem[8192];
    ske_sampling_init(mem, 64);
    uint32_t len, seq;
    CHECK(ske_sampling_latest_msg(mem, 64, &len, &seq) == NULL);
    ske_sampling_write(mem, 64, "abc", 3, 10);
    ske_sampling_write(mem, 64, "defg", 4, 20);
    uint8_t *msg = ske_sampling_latest_msg(mem, 64, &len, &seq);
    REQUIRE(msg != NULL);
    CHECK_EQ(len, 4);
    CHECK_EQ(seq, 2);
    CHECK(memcmp(msg, "defg", 4) == 0);
    msg[0] = 'X'; /* in place: what the next reader gets */
    char out[64];
    int64_t t;
    CHECK(ske_sampling_read(mem, 64, out, &len, &t));
    CHECK(memcmp(out, "Xefg", 4) == 0 && t == 20);
}

int main(void)
{
    RUN(test_fnv1a64);
    RUN(test_faults_against_the_module);
    RUN(test_switches);
    RUN(test_latest_message_in_place);
    return ske_test_result();
}
