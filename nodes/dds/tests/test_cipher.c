/* SPDX-License-Identifier: Apache-2.0 */
/* Unit test of the agent's cipher initialisations (agent_cipher.c), used as the security
 * plugin uses them: AES-GCM with 128- and 256-bit keys, a MAC over data (no output) and an
 * encryption, then the checks. Every tag and ciphertext is OpenSSL's own, a tampered tag or
 * message is refused, the implementation is the one fetched once, other ciphers pass as
 * given, and threads share it. OpenSSL's libcrypto is loaded at run time, as the plugin
 * loads it into the agent. */
#include <dlfcn.h>
#include <inttypes.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "agent__cipher.h"
#include "rpas/unit_check.h"

#define EVP_CTRL_GCM_GET_TAG 0x10 /* openssl/evp.h */
#define EVP_CTRL_GCM_SET_TAG 0x11
#define TAG 16

typedef int init_fn(EVP_CIPHER_CTX *, const EVP_CIPHER *, ENGINE *, const unsigned char *,
                    const unsigned char *);
typedef int update_fn(EVP_CIPHER_CTX *, unsigned char *, int *, const unsigned char *, int);
typedef int final_fn(EVP_CIPHER_CTX *, unsigned char *, int *);

static struct {
    init_fn *encrypt_init, *decrypt_init;
    update_fn *encrypt_update, *decrypt_update;
    final_fn *encrypt_final, *decrypt_final;
    EVP_CIPHER_CTX *(*ctx_new)(void);
    void (*ctx_free)(EVP_CIPHER_CTX *);
    int (*ctx_ctrl)(EVP_CIPHER_CTX *, int, int, void *);
    const EVP_CIPHER *(*ctx_cipher)(const EVP_CIPHER_CTX *);
    const void *(*provider)(const EVP_CIPHER *);
    const EVP_CIPHER *gcm[2], *cbc;
} ossl;

typedef struct {
    uint64_t prefetched, as_given;
} counts_t;

static counts_t counts(void)
{
    counts_t c;
    agent_cipher_counts(&c.prefetched, &c.as_given);
    return c;
}

static void fill(unsigned char *b, size_t n, uint32_t y)
{
    for (size_t i = 0; i < n; i++)
        b[i] = (unsigned char)((y = y * 1103515245u + 12345u) >> 16);
}

/* The plugin's encryption (crypto_cipher_encrypt_data): the cipher, then the key and IV;
 * the data (into `out` if given, else a MAC over it); the tag. 1 if every step succeeded. */
static int encrypt(init_fn *init, const EVP_CIPHER *type, const unsigned char *key,
                   const unsigned char *iv, const unsigned char *data, int n, unsigned char *out,
                   unsigned char tag[TAG], const EVP_CIPHER **used)
{
    EVP_CIPHER_CTX *ctx = ossl.ctx_new();
    int len = 0, ok = ctx && init(ctx, type, NULL, NULL, NULL) == 1 &&
                      init(ctx, NULL, NULL, key, iv) == 1 &&
                      ossl.encrypt_update(ctx, out, &len, data, n) == 1;
    unsigned char rest[32];
    ok = ok && ossl.encrypt_final(ctx, out ? out + len : rest, &len) == 1 &&
         ossl.ctx_ctrl(ctx, EVP_CTRL_GCM_GET_TAG, TAG, tag) == 1;
    if (used)
        *used = ctx ? ossl.ctx_cipher(ctx) : NULL;
    ossl.ctx_free(ctx);
    return ok;
}

/* The plugin's check (crypto_cipher_decrypt_data): 1 if the tag is right. */
static int decrypt(init_fn *init, const EVP_CIPHER *type, const unsigned char *key,
                   const unsigned char *iv, const unsigned char *data, int n, unsigned char *out,
                   const unsigned char tag[TAG])
{
    EVP_CIPHER_CTX *ctx = ossl.ctx_new();
    unsigned char t[TAG], rest[32];
    memcpy(t, tag, TAG);
    int len = 0, ok = ctx && init(ctx, type, NULL, NULL, NULL) == 1 &&
                      init(ctx, NULL, NULL, key, iv) == 1 &&
                      ossl.ctx_ctrl(ctx, EVP_CTRL_GCM_SET_TAG, TAG, t) == 1 &&
                      ossl.decrypt_update(ctx, out, &len, data, n) == 1 &&
                      ossl.decrypt_final(ctx, out ? out + len : rest, &len) == 1;
    ossl.ctx_free(ctx);
    return ok;
}

static void test_the_same_as_openssl(void)
{
    unsigned char key[32], iv[12], data[300], c1[300], c2[300], p[300], t1[TAG], t2[TAG];
    for (int k = 0; k < 2; k++) {
        const EVP_CIPHER *type = ossl.gcm[k], *used = NULL, *used2 = NULL;
        for (int n = 0; n <= 300; n += 13) {
            fill(key, sizeof key, (uint32_t)(k * 1000 + n));
            fill(iv, sizeof iv, (uint32_t)(n + 7));
            fill(data, sizeof data, (uint32_t)(n * 31 + 1));
            uint64_t p0 = counts().prefetched, g0 = counts().as_given;
            /* a MAC over the data, as `sign` does */
            CHECK(encrypt(EVP_EncryptInit_ex, type, key, iv, data, n, NULL, t1, &used));
            CHECK(encrypt(ossl.encrypt_init, type, key, iv, data, n, NULL, t2, NULL));
            CHECK(!memcmp(t1, t2, TAG));
            /* a provider's implementation, the same for every context (OpenSSL's own path
             * gives the same, from its method store: the counts below show ours gave it) */
            CHECK(used != NULL && used != type && ossl.provider(used) != NULL);
            CHECK(encrypt(EVP_EncryptInit_ex, type, key, iv, data, n, NULL, t1, &used2));
            CHECK(used2 == used);
            /* the MAC checked by ours; refused with a tag not the sender's */
            unsigned char bad[TAG];
            memcpy(bad, t1, TAG);
            bad[n % TAG] ^= 1;
            CHECK(decrypt(EVP_DecryptInit_ex, type, key, iv, data, n, NULL, t1));
            CHECK(!decrypt(EVP_DecryptInit_ex, type, key, iv, data, n, NULL, bad));
            /* an encryption, as `encrypt` does */
            CHECK(encrypt(EVP_EncryptInit_ex, type, key, iv, data, n, c1, t1, NULL));
            CHECK(encrypt(ossl.encrypt_init, type, key, iv, data, n, c2, t2, NULL));
            CHECK(!memcmp(c1, c2, (size_t)n) && !memcmp(t1, t2, TAG));
            /* decrypted by ours; refused when the tag or the message is not what was sent */
            CHECK(decrypt(EVP_DecryptInit_ex, type, key, iv, c1, n, p, t1));
            CHECK(!memcmp(p, data, (size_t)n));
            memcpy(bad, t1, TAG);
            bad[n % TAG] ^= 1;
            CHECK(!decrypt(EVP_DecryptInit_ex, type, key, iv, c1, n, p, bad));
            int inits = 7;
            if (n > 0) {
                c1[n / 2] ^= 0x80;
                CHECK(!decrypt(EVP_DecryptInit_ex, type, key, iv, c1, n, p, t1));
                inits++;
            }
            /* every initialisation with a cipher went through ours (the key's do not count) */
            CHECK(counts().prefetched == p0 + (uint64_t)inits);
            CHECK(counts().as_given == g0);
        }
    }
}

static void test_other_ciphers_pass_as_given(void)
{
    unsigned char key[16] = {1}, iv[16] = {2}, data[32] = {3}, out[64];
    uint64_t p0 = counts().prefetched, g0 = counts().as_given;
    EVP_CIPHER_CTX *ctx = ossl.ctx_new();
    int len = 0;
    CHECK(EVP_EncryptInit_ex(ctx, ossl.cbc, NULL, key, iv) == 1);
    CHECK(ossl.encrypt_update(ctx, out, &len, data, sizeof data) == 1 && len > 0);
    ossl.ctx_free(ctx);
    CHECK(counts().prefetched == p0 && counts().as_given == g0 + 1);
}

typedef struct {
    int k;
    int failures;
} work_t;

static void *worker(void *arg)
{
    work_t *w = arg;
    unsigned char key[32], iv[12], data[64], t1[TAG], t2[TAG];
    for (int i = 0; i < 500; i++) {
        fill(key, sizeof key, (uint32_t)(w->k * 7919 + i));
        fill(iv, sizeof iv, (uint32_t)i);
        fill(data, sizeof data, (uint32_t)(i ^ w->k));
        if (!encrypt(EVP_EncryptInit_ex, ossl.gcm[w->k % 2], key, iv, data, 64, NULL, t1, NULL) ||
            !encrypt(ossl.encrypt_init, ossl.gcm[w->k % 2], key, iv, data, 64, NULL, t2, NULL) ||
            memcmp(t1, t2, TAG) ||
            !decrypt(EVP_DecryptInit_ex, ossl.gcm[w->k % 2], key, iv, data, 64, NULL, t1))
            w->failures++;
    }
    return NULL;
}

static void test_threads(void)
{
    pthread_t t[4];
    work_t w[4];
    for (int i = 0; i < 4; i++) {
        w[i] = (work_t){i, 0};
        CHECK(pthread_create(&t[i], NULL, worker, &w[i]) == 0);
    }
    for (int i = 0; i < 4; i++) {
        pthread_join(t[i], NULL);
        CHECK(w[i].failures == 0);
    }
}

#define SYM(field, name) CHECK((*(void **)&ossl.field = dlsym(lib, name)) != NULL)

int main(void)
{
    void *lib = dlopen("libcrypto.so.3", RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "test_agent_cipher: cannot load libcrypto.so.3: %s\n", dlerror());
        return 1;
    }
    SYM(encrypt_init, "EVP_EncryptInit_ex");
    SYM(decrypt_init, "EVP_DecryptInit_ex");
    SYM(encrypt_update, "EVP_EncryptUpdate");
    SYM(decrypt_update, "EVP_DecryptUpdate");
    SYM(encrypt_final, "EVP_EncryptFinal_ex");
    SYM(decrypt_final, "EVP_DecryptFinal_ex");
    SYM(ctx_new, "EVP_CIPHER_CTX_new");
    SYM(ctx_free, "EVP_CIPHER_CTX_free");
    SYM(ctx_ctrl, "EVP_CIPHER_CTX_ctrl");
    SYM(ctx_cipher, "EVP_CIPHER_CTX_get0_cipher");
    SYM(provider, "EVP_CIPHER_get0_provider");
    const EVP_CIPHER *(*g128)(void), *(*g256)(void), *(*cbc)(void);
    CHECK((*(void **)&g128 = dlsym(lib, "EVP_aes_128_gcm")) != NULL);
    CHECK((*(void **)&g256 = dlsym(lib, "EVP_aes_256_gcm")) != NULL);
    CHECK((*(void **)&cbc = dlsym(lib, "EVP_aes_128_cbc")) != NULL);
    if (unit_failures)
        return 1;
    CHECK((void *)ossl.encrypt_init != (void *)EVP_EncryptInit_ex);
    ossl.gcm[0] = g128();
    ossl.gcm[1] = g256();
    ossl.cbc = cbc();
    /* legacy objects: no provider, OpenSSL fetches one at every initialisation */
    CHECK(ossl.provider(ossl.gcm[0]) == NULL && ossl.provider(ossl.gcm[1]) == NULL);
    test_threads(); /* first: the threads race to the agent's first look-up of OpenSSL */
    test_the_same_as_openssl();
    test_other_ciphers_pass_as_given();
    printf("test_agent_cipher: %d failures (%" PRIu64 " prefetched, %" PRIu64 " as given)\n",
           unit_failures, counts().prefetched, counts().as_given);
    return unit_failures != 0;
}
