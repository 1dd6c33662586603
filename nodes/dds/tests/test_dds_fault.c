/* SPDX-License-Identifier: Apache-2.0 */
/* Unit test of the DDS agent's faults (agent__fault.h): parsing, the decision for each frame,
 * the applied and cleared events once per spell. */
#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "agent__fault.h"
#include "rpas/unit_check.h"

#define FRAME_NS 50000000LL

static void test_parse(void)
{
    dds_faults_t set = {0};
    char err[200] = "";
    CHECK(dds_fault_add(&set, "dds_drop:fid=d,at=10s,until=12s", err, sizeof err) == 0);
    CHECK(dds_fault_add(&set, "dds_delay:fid=l,at=1s,period=2s,on=500ms,frames=3", err, sizeof err) == 0);
    CHECK(set.n == 2 && set.f[1].frames == 3 && set.f[1].kind == DDS_FAULT_DELAY);
    CHECK(!strcmp(dds_fault_class(&set.f[0]), "dds_drop"));
    static const struct {
        const char *spec, *says;
    } bad[] = {
        {"dds_delay:fid=x,at=1s", "frames=N"},
        {"dds_delay:fid=x,at=1s,frames=0", "frames=N"},
        {"dds_delay:fid=x,at=1s,frames=51", "frames=N"},
        {"dds_drop:fid=x,at=1s,frames=2", "unknown parameter"},
        {"can_drop:fid=x,at=1s", "dds_drop and dds_delay"},
        {"dds_drop:fid=d,at=1s", "given twice"},
        {"dds_drop:at=1s", "fid=ID is required"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        err[0] = '\0';
        CHECK(dds_fault_add(&set, bad[i].spec, err, sizeof err) == -1);
        if (!strstr(err, bad[i].says)) {
            fprintf(stderr, "%s: '%s' does not say '%s'\n", bad[i].spec, err, bad[i].says);
            unit_failures++;
        }
    }
    CHECK(set.n == 2);
}

static void test_frames_in_a_transient_drop(void)
{
    dds_faults_t set = {0};
    char err[200];
    CHECK(dds_fault_add(&set, "dds_drop:fid=d,at=1s,until=1200ms", err, sizeof err) == 0);
    dds_fault_note_t notes[4];
    size_t n;
    uint32_t delay;
    int withheld = 0;
    for (uint32_t f = 0; f < 40; f++) {
        int action = dds_fault_frame(&set, f, f * FRAME_NS, &delay, notes, &n);
        withheld += action == DDS_WITHHOLD;
        CHECK(action == ((f >= 20 && f < 24) ? DDS_WITHHOLD : DDS_PUBLISH));
        if (f == 20)
            CHECK(n == 1 && notes[0].applied && notes[0].t_ns == 1000000000);
        else if (f == 24)
            CHECK(n == 1 && !notes[0].applied && notes[0].t_ns == 1200000000 && notes[0].frames == 4);
        else
            CHECK(n == 0);
        /* the same frame again (its health after its inputs): same decision, no event */
        CHECK(dds_fault_frame(&set, f, f * FRAME_NS, &delay, notes, &n) == action && n == 0);
    }
    CHECK(withheld == 4 && set.f[0].total_frames == 4);
}

static void test_intermittent_delay_and_precedence(void)
{
    dds_faults_t set = {0};
    char err[200];
    CHECK(dds_fault_add(&set, "dds_delay:fid=a,at=0,period=500ms,on=100ms,until=2s,frames=2", err,
                        sizeof err) == 0);
    CHECK(dds_fault_add(&set, "dds_delay:fid=b,at=1s,until=1100ms,frames=5", err, sizeof err) == 0);
    dds_fault_note_t notes[8];
    size_t n;
    uint32_t delay;
    int applied = 0, cleared = 0;
    for (uint32_t f = 0; f < 60; f++) {
        int action = dds_fault_frame(&set, f, f * FRAME_NS, &delay, notes, &n);
        for (size_t i = 0; i < n; i++)
            notes[i].applied ? applied++ : cleared++;
        int64_t in_spell = (f * FRAME_NS) % 500000000 < 100000000 && f < 40;
        if (f == 20 || f == 21)
            CHECK(action == DDS_DELAY && delay == 5); /* both: the longer delay */
        else
            CHECK(action == (in_spell ? DDS_DELAY : DDS_PUBLISH) && (!in_spell || delay == 2));
    }
    CHECK(applied == 5 && cleared == 5); /* a: 4 spells, b: 1 */

    /* a drop wins over a delay */
    CHECK(dds_fault_add(&set, "dds_drop:fid=c,at=0", err, sizeof err) == 0);
    set.have_frame = false;
    CHECK(dds_fault_frame(&set, 100, 0, &delay, notes, &n) == DDS_WITHHOLD);
}

int main(void)
{
    test_parse();
    test_frames_in_a_transient_drop();
    test_intermittent_delay_and_precedence();
    if (unit_failures) {
        fprintf(stderr, "test_dds_fault: %d check(s) failed\n", unit_failures);
        return 1;
    }
    puts("test_dds_fault: ok");
    return 0;
}
