/* SPDX-License-Identifier: Apache-2.0 */
/* EVP_EncryptInit_ex() and EVP_DecryptInit_ex() for the DDS Security plugin: the AES-GCM
 * cipher looked up once, not at every message.
 *
 * With `sign` (or `encrypt`), Cyclone DDS 0.10's cryptographic plugin computes each RTPS
 * message's MAC (and checks each received one's) with a new cipher context set up for
 * EVP_aes_128_gcm() or EVP_aes_256_gcm(). Those are OpenSSL's legacy cipher objects: given
 * one, OpenSSL 3 fetches the provider's implementation by name at every initialisation,
 * `EVP_CIPHER_fetch(NULL, OBJ_nid2sn(nid), "")`, a look-up in its method store under a
 * lock. Once the session keys are reused (agent_hmac.c), that fetch was 4.3% of an agent's
 * CPU in a triplex flight (perf, with call graphs: docs/performance.md).
 *
 * The agent defines both functions and exports them (the link option in CMakeLists.txt), so
 * the plugin binds to them as it does to HMAC(). Given one of the two legacy GCM objects and
 * no engine, they pass OpenSSL the implementation fetched once with that same call, kept for
 * the process's life; everything else, and every argument but the cipher, goes to OpenSSL
 * as given. OpenSSL would have used the very implementation it fetched: every MAC, every
 * check and every ciphertext is the same. An ENGINE that registers AES-GCM still takes over
 * (OpenSSL asks for one by the cipher's identifier, the same for both objects). A context
 * bound to an ENGINE by an earlier initialisation would take OpenSSL's legacy path, which the
 * fetched implementation does not serve; the agent uses no ENGINE, and the plugin makes a new
 * context for each message.
 *
 * Being the executable's, these definitions are every caller's in the process, not the
 * plugin's alone (libcrypto's own calls too, unless it binds its symbols to itself): each
 * call is OpenSSL's with that one argument swapped, and `cipher_inits.as_given` counts the
 * initialisations with any other cipher (none in a flight). */
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "agent__cipher.h"
#include "agent__libcrypto.h"

typedef int init_fn(EVP_CIPHER_CTX *ctx, const EVP_CIPHER *type, ENGINE *impl,
                    const unsigned char *key, const unsigned char *iv);
typedef const EVP_CIPHER *cipher_fn(void);
typedef EVP_CIPHER *fetch_fn(void *libctx, const char *algorithm, const char *properties);
typedef int nid_fn(const EVP_CIPHER *cipher);
typedef const char *sn_fn(int nid);

static struct {
    init_fn *encrypt_init, *decrypt_init; /* OpenSSL's */
    const EVP_CIPHER *legacy[2];          /* EVP_aes_128_gcm(), EVP_aes_256_gcm() */
    EVP_CIPHER *fetched[2];               /* their implementations, or NULL */
} ossl;
static pthread_mutex_t lookup = PTHREAD_MUTEX_INITIALIZER;
static atomic_bool ready; /* ossl is complete: read without the lock from then on */
static atomic_uint_fast64_t prefetched, as_given;

/* OpenSSL's functions and the two implementations, looked up at the first call that finds
 * libcrypto loaded (until then, each call tries again). */
static bool look_up(void)
{
    if (atomic_load_explicit(&ready, memory_order_acquire))
        return true;
    pthread_mutex_lock(&lookup);
    if (!atomic_load_explicit(&ready, memory_order_relaxed)) {
        ossl.encrypt_init = (init_fn *)agent_libcrypto_sym("EVP_EncryptInit_ex");
        ossl.decrypt_init = (init_fn *)agent_libcrypto_sym("EVP_DecryptInit_ex");
        fetch_fn *fetch = (fetch_fn *)agent_libcrypto_sym("EVP_CIPHER_fetch");
        nid_fn *nid = (nid_fn *)agent_libcrypto_sym("EVP_CIPHER_get_nid");
        sn_fn *short_name = (sn_fn *)agent_libcrypto_sym("OBJ_nid2sn");
        const char *names[2] = {"EVP_aes_128_gcm", "EVP_aes_256_gcm"};
        for (int i = 0; ossl.encrypt_init && ossl.decrypt_init && i < 2; i++) {
            cipher_fn *legacy = (cipher_fn *)agent_libcrypto_sym(names[i]);
            if (!legacy || !fetch || !nid || !short_name)
                continue; /* passed on as given: OpenSSL fetches, as without the agent's */
            ossl.legacy[i] = legacy();
            const char *sn = ossl.legacy[i] ? short_name(nid(ossl.legacy[i])) : NULL;
            ossl.fetched[i] = sn ? fetch(NULL, sn, "") : NULL; /* kept for the process's life */
        }
        if (ossl.encrypt_init && ossl.decrypt_init)
            atomic_store_explicit(&ready, true, memory_order_release);
    }
    pthread_mutex_unlock(&lookup);
    return atomic_load_explicit(&ready, memory_order_acquire);
}

static const EVP_CIPHER *implementation(const EVP_CIPHER *type, const ENGINE *impl)
{
    if (type && !impl)
        for (int i = 0; i < 2; i++)
            if (type == ossl.legacy[i] && ossl.fetched[i]) {
                atomic_fetch_add_explicit(&prefetched, 1, memory_order_relaxed);
                return ossl.fetched[i];
            }
    if (type)
        atomic_fetch_add_explicit(&as_given, 1, memory_order_relaxed);
    return type;
}

static int missing(const char *name)
{
    static atomic_flag told = ATOMIC_FLAG_INIT;
    if (!atomic_flag_test_and_set(&told))
        fprintf(stderr, "ima-dds-node: OpenSSL's %s() not found: DDS Security cannot work\n",
                name);
    return 0; /* OpenSSL's failure */
}

int EVP_EncryptInit_ex(EVP_CIPHER_CTX *ctx, const EVP_CIPHER *type, ENGINE *impl,
                       const unsigned char *key, const unsigned char *iv)
{
    if (!look_up())
        return missing("EVP_EncryptInit_ex");
    return ossl.encrypt_init(ctx, implementation(type, impl), impl, key, iv);
}

int EVP_DecryptInit_ex(EVP_CIPHER_CTX *ctx, const EVP_CIPHER *type, ENGINE *impl,
                       const unsigned char *key, const unsigned char *iv)
{
    if (!look_up())
        return missing("EVP_DecryptInit_ex");
    return ossl.decrypt_init(ctx, implementation(type, impl), impl, key, iv);
}

void agent_cipher_counts(uint64_t *prefetched_, uint64_t *as_given_)
{
    *prefetched_ = atomic_load_explicit(&prefetched, memory_order_relaxed);
    *as_given_ = atomic_load_explicit(&as_given, memory_order_relaxed);
}
