/* SPDX-License-Identifier: Apache-2.0 */
/* The agent's HMAC() (agent_hmac.c): what it reused and what it had OpenSSL derive. */
#ifndef IMA_AGENT_HMAC_H
#define IMA_AGENT_HMAC_H

#include <stddef.h>
#include <stdint.h>

typedef struct evp_md_st EVP_MD; /* OpenSSL's, opaque here: no OpenSSL headers needed */

/* OpenSSL's one-shot HMAC(), with its contract; the agent's is the security plugin's. */
unsigned char *HMAC(const EVP_MD *md, const void *key, int key_len, const unsigned char *data,
                    size_t data_len, unsigned char *out, unsigned int *out_len);

/* Calls answered from a thread's stored results, and calls passed on to OpenSSL, since the
 * process started (every thread). */
void agent_hmac_counts(uint64_t *reused, uint64_t *derived);

#endif
