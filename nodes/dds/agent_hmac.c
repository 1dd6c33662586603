/* SPDX-License-Identifier: Apache-2.0 */
/* HMAC() for the DDS Security plugin: a session key derived once per thread, peer and
 * session, not once per message.
 *
 * With `sign` (or `encrypt`), Cyclone DDS 0.10's cryptographic plugin derives the sending
 * participant's session key again for every RTPS message it receives: HMAC-SHA256 over the
 * same master key, the same salt and the same session id, with OpenSSL's one-shot HMAC().
 * OpenSSL 3 implements that by fetching the algorithm and building its contexts at every
 * call: about 2 µs a message, 9% of an agent's CPU in a triplex flight (perf, with call
 * graphs: docs/performance.md).
 *
 * The agent defines HMAC() itself and exports it (the link option in CMakeLists.txt). The
 * plugin, loaded later, has its reference bound to the executable's definition, which comes
 * first in the global scope; so it calls this one. This one keeps the last results of its
 * thread and returns one when the digest, the key and the data are the same to the byte;
 * otherwise it calls OpenSSL's HMAC(). An HMAC is a function of those three alone, so every
 * result is OpenSSL's. Nothing else changes: each message's MAC is still checked with the
 * session key, a tampered message is still refused.
 *
 * A result is found again only while its thread keeps it: 8 per thread, the oldest replaced
 * first; past 8 peers and sessions at once, each message is derived again, as before. The
 * digest is known by its object (the plugin's EVP_sha256(), a static one), not its name.
 * The comparisons take the same time whatever bytes differ. A slot is wiped before it is
 * used again; the key material it holds otherwise stays until the thread ends. */
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "agent__hmac.h"
#include "agent__libcrypto.h"

#define KEY_MAX 64   /* bytes of key and of data kept; longer ones are not stored */
#define DATA_MAX 128
#define OUT_MAX 64   /* EVP_MAX_MD_SIZE */
#define ENTRIES 8    /* per thread: a session key per peer participant, a few peers */

typedef unsigned char *hmac_fn(const EVP_MD *md, const void *key, int key_len,
                               const unsigned char *data, size_t data_len, unsigned char *out,
                               unsigned int *out_len);

typedef struct {
    const EVP_MD *md;
    unsigned key_len, data_len, out_len;
    unsigned char key[KEY_MAX], data[DATA_MAX], out[OUT_MAX];
} entry_t;

static _Thread_local entry_t cache[ENTRIES];
static _Thread_local unsigned cached, next_slot;
static atomic_uint_fast64_t hits, misses;

/* OpenSSL's HMAC() (agent__libcrypto.h). */
static hmac_fn *openssl_hmac(void)
{
    static hmac_fn *_Atomic fn;
    hmac_fn *f = atomic_load_explicit(&fn, memory_order_acquire);
    if (f)
        return f;
    f = (hmac_fn *)agent_libcrypto_sym("HMAC");
    if (!f) {
        static atomic_flag told = ATOMIC_FLAG_INIT;
        if (!atomic_flag_test_and_set(&told))
            fputs("ima-dds-node: OpenSSL's HMAC() not found: DDS Security cannot work\n", stderr);
        return NULL;
    }
    atomic_store_explicit(&fn, f, memory_order_release);
    return f;
}

/* Equal or not, in a time that depends only on n. */
static int same_bytes(const unsigned char *a, const unsigned char *b, size_t n)
{
    unsigned char d = 0;
    for (size_t i = 0; i < n; i++)
        d |= (unsigned char)(a[i] ^ b[i]);
    return d == 0;
}

unsigned char *HMAC(const EVP_MD *md, const void *key, int key_len, const unsigned char *data,
                    size_t data_len, unsigned char *out, unsigned int *out_len)
{
    hmac_fn *real = openssl_hmac();
    if (!real)
        return NULL;
    /* OpenSSL's static buffer (out NULL), odd lengths: OpenSSL's, unstored */
    if (!out || !md || !key || key_len < 0 || (unsigned)key_len > KEY_MAX ||
        (!data && data_len) || data_len > DATA_MAX) {
        atomic_fetch_add_explicit(&misses, 1, memory_order_relaxed);
        return real(md, key, key_len, data, data_len, out, out_len);
    }
    for (unsigned i = 0; i < cached; i++) {
        const entry_t *e = &cache[i];
        if (e->md != md || e->key_len != (unsigned)key_len || e->data_len != data_len)
            continue;
        /* both compared whole: the time does not tell which differs */
        int same = same_bytes(e->key, key, (size_t)key_len);
        same &= same_bytes(e->data, data, data_len);
        if (same) {
            memcpy(out, e->out, e->out_len);
            if (out_len)
                *out_len = e->out_len;
            atomic_fetch_add_explicit(&hits, 1, memory_order_relaxed);
            return out;
        }
    }
    /* into a buffer of its own: `out` may be the key or the data (an HMAC in place), which
     * must be stored as they were given */
    unsigned char digest[OUT_MAX];
    unsigned int n = 0;
    atomic_fetch_add_explicit(&misses, 1, memory_order_relaxed);
    if (real(md, key, key_len, data, data_len, digest, &n) != digest || n == 0) {
        explicit_bzero(digest, sizeof digest);
        return NULL; /* OpenSSL's answer: failed */
    }
    entry_t *e = &cache[next_slot];
    next_slot = (next_slot + 1) % ENTRIES;
    if (cached < ENTRIES)
        cached++;
    explicit_bzero(e, sizeof *e);
    e->md = md;
    e->key_len = (unsigned)key_len;
    e->data_len = (unsigned)data_len;
    e->out_len = n;
    memcpy(e->key, key, (size_t)key_len);
    if (data_len)
        memcpy(e->data, data, data_len);
    memcpy(e->out, digest, n);
    memcpy(out, digest, n);
    explicit_bzero(digest, sizeof digest);
    if (out_len)
        *out_len = n;
    return out;
}

void agent_hmac_counts(uint64_t *reused, uint64_t *derived)
{
    *reused = atomic_load_explicit(&hits, memory_order_relaxed);
    *derived = atomic_load_explicit(&misses, memory_order_relaxed);
}
