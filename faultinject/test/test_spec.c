/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the fault spec every injector reads: parsing, errors, durations, spells. */
#include <stdio.h>
#include <string.h>

#include "fi/spec.h"

static int failures;
#define CHECK(c)                                                                                   \
    do {                                                                                           \
        if (!(c)) {                                                                                \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #c);                  \
            failures++;                                                                            \
        }                                                                                          \
    } while (0)

static void test_permanent(void)
{
    fi_spec_t s;
    char err[200] = "";
    CHECK(fi_spec_parse("memory_violation:fid=f1,at=60s,process=nav_fcs", &s, err, sizeof err) == 0);
    CHECK(!strcmp(s.cls, "memory_violation") && !strcmp(s.fid, "f1"));
    CHECK(s.at_ns == 60000000000LL && s.until_ns == FI_NEVER && s.duration == FI_PERMANENT);
    CHECK(!strcmp(fi_spec_param(&s, "process"), "nav_fcs") && !fi_spec_param(&s, "port"));
    CHECK(fi_spec_spell(&s, 59999999999LL) == -1 && fi_spec_spell(&s, 60000000000LL) == 0);
    CHECK(fi_spec_spell(&s, 1LL << 62) == 0 && fi_spec_end(&s) == FI_NEVER);
}

static void test_transient_and_units(void)
{
    fi_spec_t s;
    char err[200];
    CHECK(fi_spec_parse("can_drop:fid=x-2,from=1.5s,until=1600ms,id=0x8d80640", &s, err, sizeof err) == 0);
    CHECK(s.at_ns == 1500000000LL && s.until_ns == 1600000000LL && s.duration == FI_TRANSIENT);
    CHECK(fi_spec_spell(&s, 1599999999LL) == 0 && fi_spec_spell(&s, 1600000000LL) == -1);
    CHECK(!strcmp(fi_spec_param(&s, "id"), "0x8d80640"));
    int64_t t;
    CHECK(fi_parse_time("250us", &t) == 0 && t == 250000);
    CHECK(fi_parse_time("7", &t) == 0 && t == 7);
    CHECK(fi_parse_time("7 s", &t) == -1 && fi_parse_time("-1s", &t) == -1 && fi_parse_time("nan", &t) == -1);
}

static void test_intermittent(void)
{
    fi_spec_t s;
    char err[200];
    CHECK(fi_spec_parse("gps_loss:fid=g,at=10s,period=4s,on=1s,until=30s", &s, err, sizeof err) == 0);
    CHECK(s.duration == FI_INTERMITTENT);
    CHECK(fi_spec_spell(&s, 10000000000LL) == 0 && fi_spec_spell(&s, 10999999999LL) == 0);
    CHECK(fi_spec_spell(&s, 11000000000LL) == -1 && fi_spec_spell(&s, 14500000000LL) == 1);
    CHECK(fi_spec_spell_start(&s, 2) == 18000000000LL);
    CHECK(fi_spec_spell(&s, 30000000000LL) == -1);
    double v;
    CHECK(fi_spec_double(&s, "value", 0.5, &v) == 0 && v == 0.5);
}

static void test_refused(void)
{
    static const struct {
        const char *spec, *says;
    } bad[] = {
        {"Memory:fid=a,at=1s", "a fault class"},
        {"crash:at=1s", "fid=ID is required"},
        {"crash:fid=a", "at=TIME is required"},
        {"crash:fid=a b,at=1s", "fid 'a b'"},
        {"crash:fid=0123456789abcdef,at=1s", "fid '0123456789abcdef'"},
        {"crash:fid=a,at=2s,until=1s", "until must be after at"},
        {"crash:fid=a,at=1s,period=1s", "both period and on"},
        {"crash:fid=a,at=1s,period=1s,on=2s", "0 < on <= period"},
        {"crash:fid=a,at=1h", "bad time '1h' for 'at'"},
        {"crash:fid=a,at=1s,x", "'x': expected KEY=VALUE"},
        {"crash:fid=a,at=1s,k=1,k=2", "given twice"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        fi_spec_t s;
        char err[200] = "";
        CHECK(fi_spec_parse(bad[i].spec, &s, err, sizeof err) == -1);
        if (!strstr(err, bad[i].says)) {
            fprintf(stderr, "%s: '%s' does not say '%s'\n", bad[i].spec, err, bad[i].says);
            failures++;
        }
    }
    fi_spec_t s;
    CHECK(fi_spec_parse(NULL, &s, NULL, 0) == -1);
    CHECK(!strcmp(fi_duration_name(FI_INTERMITTENT), "intermittent"));
}

int main(void)
{
    test_permanent();
    test_transient_and_units();
    test_intermittent();
    test_refused();
    if (failures)
        fprintf(stderr, "%d check(s) failed\n", failures);
    else
        printf("ok test_spec\n");
    return failures ? 1 : 0;
}
