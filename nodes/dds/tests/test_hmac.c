/* SPDX-License-Identifier: Apache-2.0 */
/* Unit test of the agent's HMAC() (agent_hmac.c): every result is OpenSSL's own, for two
 * digests, keys and data of every length it stores and some it does not, in place too; a
 * result is reused only for the same digest, key and data; each thread keeps its own.
 * OpenSSL's libcrypto is loaded at run time, as the security plugin loads it into the agent. */
#include <dlfcn.h>
#include <inttypes.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "agent__hmac.h"
#include "rpas/unit_check.h"

typedef unsigned char *hmac_fn(const EVP_MD *md, const void *key, int key_len,
                               const unsigned char *data, size_t data_len, unsigned char *out,
                               unsigned int *out_len);
typedef const EVP_MD *md_fn(void);

static hmac_fn *openssl;
static const EVP_MD *sha256, *sha1;

static uint64_t reused(void)
{
    uint64_t r, d;
    agent_hmac_counts(&r, &d);
    return r;
}

static uint64_t derived(void)
{
    uint64_t r, d;
    agent_hmac_counts(&r, &d);
    return d;
}

/* ours and OpenSSL's agree on (md, key, data) */
static void same_as_openssl(const EVP_MD *md, const unsigned char *key, int key_len,
                            const unsigned char *data, size_t n)
{
    unsigned char a[64], b[64];
    unsigned int la = 0, lb = 0;
    memset(a, 0xAA, sizeof a);
    memset(b, 0x55, sizeof b);
    CHECK(HMAC(md, key, key_len, data, n, a, &la) == a);
    CHECK(openssl(md, key, key_len, data, n, b, &lb) == b);
    CHECK(la == lb && la > 0 && !memcmp(a, b, la));
}

static void test_rfc4231_vector(void)
{
    /* RFC 4231, test case 2 */
    static const unsigned char want[32] = {
        0x5b, 0xdc, 0xc1, 0x46, 0xbf, 0x60, 0x75, 0x4e, 0x6a, 0x04, 0x24, 0x26, 0x08, 0x95, 0x75, 0xc7,
        0x5a, 0x00, 0x3f, 0x08, 0x9d, 0x27, 0x39, 0x83, 0x9d, 0xec, 0x58, 0xb9, 0x64, 0xec, 0x38, 0x43};
    const char *data = "what do ya want for nothing?";
    unsigned char out[64];
    unsigned int n = 0;
    uint64_t r0 = reused(), d0 = derived();
    CHECK(HMAC(sha256, "Jefe", 4, (const unsigned char *)data, strlen(data), out, &n) == out);
    CHECK(n == 32 && !memcmp(out, want, 32));
    CHECK(derived() == d0 + 1 && reused() == r0);
    memset(out, 0, sizeof out);
    n = 0;
    CHECK(HMAC(sha256, "Jefe", 4, (const unsigned char *)data, strlen(data), out, &n) == out);
    CHECK(n == 32 && !memcmp(out, want, 32));
    CHECK(derived() == d0 + 1 && reused() == r0 + 1);
    /* no length asked for */
    memset(out, 0, sizeof out);
    CHECK(HMAC(sha256, "Jefe", 4, (const unsigned char *)data, strlen(data), out, NULL) == out);
    CHECK(!memcmp(out, want, 32));
}

static void fill(unsigned char *b, size_t n, uint32_t y)
{
    for (size_t i = 0; i < n; i++)
        b[i] = (unsigned char)((y = y * 1103515245u + 12345u) >> 16);
}

static void test_every_length_and_eviction(void)
{
    unsigned char key[64], data[128];
    /* every key length with every data length it stores, each twice (derived, then stored) */
    for (int kl = 0; kl <= 64; kl++)
        for (size_t dl = 0; dl <= 128; dl++) {
            fill(key, sizeof key, (uint32_t)(kl * 1000 + (int)dl));
            fill(data, sizeof data, (uint32_t)(kl * 7 + (int)dl * 13));
            const EVP_MD *md = (kl + dl) % 3 ? sha256 : sha1;
            same_as_openssl(md, key, kl, data, dl);
            same_as_openssl(md, key, kl, data, dl);
        }
    /* 40 inputs in turn, more than a thread keeps: each is derived again, rightly */
    for (int round = 0; round < 3; round++)
        for (int i = 0; i < 40; i++) {
            fill(key, sizeof key, 12345u + (uint32_t)i);
            fill(data, sizeof data, 54321u + (uint32_t)i);
            same_as_openssl(i % 3 ? sha256 : sha1, key, (i * 7) % 65, data, (size_t)((i * 13) % 129));
        }
}

static void test_in_place(void)
{
    /* the digest written over the data, then over the key, round after round: each round's
     * input differs from the last, and so must its result */
    unsigned char buf[32], key[32], want[32], kw[32];
    unsigned int n;
    fill(buf, sizeof buf, 7);
    fill(key, sizeof key, 8);
    memcpy(want, buf, sizeof want);
    memcpy(kw, key, sizeof kw);
    for (int i = 0; i < 20; i++) {
        CHECK(HMAC(sha256, key, 32, buf, 32, buf, &n) == buf && n == 32);
        CHECK(openssl(sha256, kw, 32, want, 32, want, &n) == want && n == 32);
        CHECK(!memcmp(buf, want, 32));
        CHECK(HMAC(sha256, key, 32, buf, 32, key, &n) == key && n == 32);
        CHECK(openssl(sha256, kw, 32, want, 32, kw, &n) == kw && n == 32);
        CHECK(!memcmp(key, kw, 32));
    }
}

static void test_only_the_same_input_is_reused(void)
{
    unsigned char key[32], data[46], a[64], b[64];
    unsigned int la, lb;
    for (int i = 0; i < 32; i++)
        key[i] = (unsigned char)i;
    for (int i = 0; i < 46; i++)
        data[i] = (unsigned char)(100 + i);
    CHECK(HMAC(sha256, key, 32, data, 46, a, &la) == a);
    /* one bit of the data's last byte, of the key's first byte, the digest, a length */
    data[45] ^= 1;
    CHECK(HMAC(sha256, key, 32, data, 46, b, &lb) == b && lb == la && memcmp(a, b, la));
    same_as_openssl(sha256, key, 32, data, 46);
    data[45] ^= 1;
    key[0] ^= 0x80;
    CHECK(HMAC(sha256, key, 32, data, 46, b, &lb) == b && memcmp(a, b, la));
    same_as_openssl(sha256, key, 32, data, 46);
    key[0] ^= 0x80;
    CHECK(HMAC(sha1, key, 32, data, 46, b, &lb) == b && lb == 20);
    same_as_openssl(sha1, key, 32, data, 46);
    CHECK(HMAC(sha256, key, 31, data, 46, b, &lb) == b && memcmp(a, b, la));
    same_as_openssl(sha256, key, 31, data, 46);
    CHECK(HMAC(sha256, key, 32, data, 45, b, &lb) == b && memcmp(a, b, la));
    same_as_openssl(sha256, key, 32, data, 45);
    /* and the original still comes back right */
    CHECK(HMAC(sha256, key, 32, data, 46, b, &lb) == b && lb == la && !memcmp(a, b, la));
}

static void test_what_is_not_stored(void)
{
    unsigned char key[100], data[200], out[64], want[64];
    unsigned int n, m;
    memset(key, 7, sizeof key);
    memset(data, 9, sizeof data);
    /* a key or data too long to keep: OpenSSL's result every time */
    for (int i = 0; i < 2; i++) {
        uint64_t r0 = reused(), d0 = derived();
        CHECK(HMAC(sha256, key, 100, data, 20, out, &n) == out);
        CHECK(openssl(sha256, key, 100, data, 20, want, &m) == want && n == m && !memcmp(out, want, n));
        CHECK(HMAC(sha256, key, 20, data, 200, out, &n) == out);
        CHECK(openssl(sha256, key, 20, data, 200, want, &m) == want && n == m && !memcmp(out, want, n));
        CHECK(reused() == r0 && derived() == d0 + 2);
    }
    /* no output buffer: OpenSSL's own static one */
    unsigned char *s = HMAC(sha256, key, 20, data, 20, NULL, &n);
    CHECK(s != NULL);
    CHECK(openssl(sha256, key, 20, data, 20, want, &m) == want && s && n == m && !memcmp(s, want, n));
    /* an empty key and empty data are inputs like any other */
    same_as_openssl(sha256, key, 0, data, 0);
    same_as_openssl(sha256, key, 0, NULL, 0);
}

static void *other_thread(void *arg)
{
    (void)arg;
    unsigned char out[64];
    unsigned int n;
    uint64_t d0 = derived();
    /* stored by the main thread, not by this one */
    HMAC(sha256, "Jefe", 4, (const unsigned char *)"what do ya want for nothing?", 28, out, &n);
    CHECK(derived() == d0 + 1);
    same_as_openssl(sha256, (const unsigned char *)"Jefe", 4,
                    (const unsigned char *)"what do ya want for nothing?", 28);
    return NULL;
}

static void test_threads_keep_their_own(void)
{
    pthread_t t;
    CHECK(pthread_create(&t, NULL, other_thread, NULL) == 0);
    CHECK(pthread_join(t, NULL) == 0);
}

int main(void)
{
    void *lib = dlopen("libcrypto.so.3", RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "test_agent_hmac: cannot load libcrypto.so.3: %s\n", dlerror());
        return 1;
    }
    openssl = (hmac_fn *)dlsym(lib, "HMAC");
    md_fn *s256 = (md_fn *)dlsym(lib, "EVP_sha256"), *s1 = (md_fn *)dlsym(lib, "EVP_sha1");
    if (!openssl || !s256 || !s1) {
        fprintf(stderr, "test_agent_hmac: libcrypto.so.3 lacks HMAC or EVP_sha256\n");
        return 1;
    }
    CHECK(openssl != HMAC);
    sha256 = s256();
    sha1 = s1();
    test_rfc4231_vector();
    test_every_length_and_eviction();
    test_in_place();
    test_only_the_same_input_is_reused();
    test_what_is_not_stored();
    test_threads_keep_their_own();
    if (unit_failures) {
        fprintf(stderr, "test_agent_hmac: %d check(s) failed\n", unit_failures);
        return 1;
    }
    printf("test_agent_hmac: ok (%" PRIu64 " reused, %" PRIu64 " derived)\n", reused(), derived());
    return 0;
}
