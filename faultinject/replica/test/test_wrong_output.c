/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the arbitrary-value replica: parsing, each mode's values, the spells and the
 * reports (applied and cleared once per spell), determinism of the random mode. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fi/wrong_output.h"

static int failures;
#define CHECK(c)                                                                                   \
    do {                                                                                           \
        if (!(c)) {                                                                                \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #c);                  \
            failures++;                                                                            \
        }                                                                                          \
    } while (0)
#define NEAR(a, b) (fabs((a) - (b)) < 1e-12)

static const fi_wo_axis_t axes[] = {{"elev", -1, 1}, {"ail", -1, 1}, {"rud", -1, 1}, {"thr", 0, 1}};
#define S 1000000000LL

static fi_wo_t parse_ok(const char *text)
{
    fi_wo_t f;
    char err[200] = "";
    int rc = fi_wo_parse(text, axes, 4, &f, err, sizeof err);
    if (rc) {
        fprintf(stderr, "%s: %s\n", text, err);
        failures++;
    }
    return f;
}

static void test_parse(void)
{
    fi_wo_t f = parse_ok("wrong_output:fid=w1,at=10s,mode=bias,axis=rud,value=-0.25");
    CHECK(f.mode == FI_WO_BIAS && f.axis == 2 && f.value == -0.25 && f.spec.at_ns == 10 * S);
    CHECK(f.lo == -1 && f.hi == 1 && !strcmp(f.axis_name, "rud"));
    f = parse_ok("wrong_output:fid=w2,at=0,until=5s,mode=oscillating,axis=thr,value=0.2,period_osc=500ms");
    CHECK(f.mode == FI_WO_OSCILLATING && f.period_osc_ns == S / 2 && f.lo == 0);
    f = parse_ok("wrong_output:fid=w3,at=1s,mode=random,axis=elev,seed=42");
    CHECK(f.seed == 42 && f.period_osc_ns == S);
    f = parse_ok("wrong_output:fid=w4,at=1s,mode=hardover,axis=ail");
    CHECK(f.value == 1);

    static const struct {
        const char *text, *says;
    } bad[] = {
        {"wrong_output:fid=a,at=1s,axis=elev,value=1", "mode="},
        {"wrong_output:fid=a,at=1s,mode=stuck,axis=elev", "mode="},
        {"wrong_output:fid=a,at=1s,mode=bias,axis=yaw,value=1", "axis=yaw"},
        {"wrong_output:fid=a,at=1s,mode=bias,axis=elev", "needs value"},
        {"wrong_output:fid=a,at=1s,mode=oscillating,axis=elev,value=x", "value"},
        {"wrong_output:fid=a,at=1s,mode=oscillating,axis=elev,value=1,period_osc=0", "period_osc"},
        {"wrong_output:fid=a,at=1s,mode=random,axis=elev,seed=-1", "seed"},
        {"wrong_output:fid=a,at=1s,mode=random,axis=elev,colour=red", "unknown parameter"},
        {"stuck_output:fid=a,at=1s,mode=bias,axis=elev,value=1", "not a wrong_output"},
        {"wrong_output:at=1s,mode=bias,axis=elev,value=1", "fid"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        fi_wo_t g;
        char err[200] = "";
        CHECK(fi_wo_parse(bad[i].text, axes, 4, &g, err, sizeof err) == -1);
        if (!strstr(err, bad[i].says)) {
            fprintf(stderr, "%s: '%s' does not say '%s'\n", bad[i].text, err, bad[i].says);
            failures++;
        }
    }
}

static void test_bias_and_reports(void)
{
    fi_wo_t f = parse_ok("wrong_output:fid=b1,at=1s,until=2s,mode=bias,axis=elev,value=0.3");
    fi_wo_state_t st;
    fi_wo_reset(&st);
    fi_wo_reports_t rep;
    double x = 0.1;
    fi_wo_apply(&f, &st, S - 1, &x, &rep);
    CHECK(x == 0.1 && rep.n == 0);
    fi_wo_apply(&f, &st, S, NULL, &rep); /* no output this time: nothing applied yet */
    CHECK(rep.n == 0 && st.spell == -1);
    fi_wo_apply(&f, &st, S + 50, &x, &rep);
    CHECK(NEAR(x, 0.4) && rep.n == 1);
    CHECK(!strcmp(rep.line[0], "fault b1 wrong_output applied mode=bias axis=elev value=0.3"));
    x = 0.1;
    fi_wo_apply(&f, &st, S + 100, &x, &rep);
    CHECK(NEAR(x, 0.4) && rep.n == 0); /* once per spell */
    x = 0.1;
    fi_wo_apply(&f, &st, 2 * S, &x, &rep);
    CHECK(x == 0.1 && rep.n == 1);
    CHECK(!strcmp(rep.line[0], "fault b1 wrong_output cleared mode=bias axis=elev value=0.3 frames=2"));
    fi_wo_apply(&f, &st, 3 * S, &x, &rep);
    CHECK(rep.n == 0);
}

static void test_intermittent_reports_each_spell(void)
{
    fi_wo_t f = parse_ok("wrong_output:fid=i,at=0,period=1s,on=100ms,mode=hardover,axis=thr,value=-1");
    fi_wo_state_t st;
    fi_wo_reset(&st);
    fi_wo_reports_t rep;
    int applied = 0, cleared = 0;
    for (int64_t t = 0; t < 3 * S; t += S / 20) {
        double x = 0.5;
        fi_wo_apply(&f, &st, t, &x, &rep);
        for (int i = 0; i < rep.n; i++) {
            applied += strstr(rep.line[i], " applied ") != NULL;
            cleared += strstr(rep.line[i], " cleared ") != NULL;
        }
        bool on = (t % S) < S / 10;
        CHECK(x == (on ? 0.0 : 0.5)); /* hardover to thr's lower limit */
    }
    CHECK(applied == 3 && cleared == 3);
    /* a spell that ends while a next one starts between two calls: cleared, then applied */
    fi_wo_t g = parse_ok("wrong_output:fid=j,at=0,period=100ms,on=60ms,mode=bias,axis=ail,value=1");
    fi_wo_reset(&st);
    double x = 0;
    fi_wo_apply(&g, &st, 0, &x, &rep);
    fi_wo_apply(&g, &st, S / 10, &x, &rep);
    CHECK(rep.n == 2 && strstr(rep.line[0], " cleared ") && strstr(rep.line[1], " applied "));
}

static void test_random_and_oscillating(void)
{
    fi_wo_t f = parse_ok("wrong_output:fid=r,at=0,mode=random,axis=elev,seed=7");
    fi_wo_t g = parse_ok("wrong_output:fid=r,at=0,mode=random,axis=elev,seed=8");
    fi_wo_state_t a, b, c;
    fi_wo_reset(&a);
    fi_wo_reset(&b);
    fi_wo_reset(&c);
    fi_wo_reports_t rep;
    double sum = 0, lo = 1, hi = -1;
    int same_as_other_seed = 0;
    const int n = 2000;
    for (int i = 0; i < n; i++) {
        int64_t t = (int64_t)i * 50000000 + 20000000;
        double x = 0.1, y = 0.1, z = 0.1;
        fi_wo_apply(&f, &a, t, &x, &rep);
        fi_wo_apply(&f, &b, t, &y, &rep); /* same seed, same time: same value */
        fi_wo_apply(&g, &c, t, &z, &rep);
        CHECK(x == y && x >= -1 && x < 1);
        same_as_other_seed += x == z;
        sum += x;
        lo = x < lo ? x : lo;
        hi = x > hi ? x : hi;
    }
    CHECK(same_as_other_seed == 0);
    CHECK(fabs(sum / n) < 0.06 && lo < -0.95 && hi > 0.95); /* uniform over [-1, 1) */

    fi_wo_t o = parse_ok("wrong_output:fid=o,at=1s,mode=oscillating,axis=rud,value=0.5,period_osc=2s");
    fi_wo_reset(&a);
    double x = 0.1;
    fi_wo_apply(&o, &a, S, &x, &rep); /* the spell's start: sin 0 */
    CHECK(NEAR(x, 0.1));
    x = 0.1;
    fi_wo_apply(&o, &a, S + S / 2, &x, &rep); /* a quarter period on */
    CHECK(NEAR(x, 0.6));
    x = 0.1;
    fi_wo_apply(&o, &a, 2 * S + S / 2, &x, &rep);
    CHECK(NEAR(x, -0.4));
    char d[80];
    fi_wo_describe(&o, d, sizeof d);
    CHECK(!strcmp(d, "mode=oscillating axis=rud value=0.5 period_osc=2s"));
}

int main(void)
{
    test_parse();
    test_bias_and_reports();
    test_intermittent_reports_each_spell();
    test_random_and_oscillating();
    if (failures)
        fprintf(stderr, "%d check(s) failed\n", failures);
    else
        printf("ok test_fi_wrong_output\n");
    return failures ? 1 : 0;
}
