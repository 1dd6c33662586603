/* SPDX-License-Identifier: Apache-2.0 */
/* The agent's EVP_EncryptInit_ex() and EVP_DecryptInit_ex() (agent_cipher.c): how many
 * initialisations it gave the AES-GCM implementation fetched once, and how many it passed on
 * with the cipher as given. */
#ifndef IMA_AGENT_CIPHER_H
#define IMA_AGENT_CIPHER_H

#include <stdint.h>

/* OpenSSL's, opaque here: no OpenSSL headers needed */
typedef struct evp_cipher_st EVP_CIPHER;
typedef struct evp_cipher_ctx_st EVP_CIPHER_CTX;
typedef struct engine_st ENGINE;

/* OpenSSL's, with their contract; the agent's are the security plugin's. */
int EVP_EncryptInit_ex(EVP_CIPHER_CTX *ctx, const EVP_CIPHER *type, ENGINE *impl,
                       const unsigned char *key, const unsigned char *iv);
int EVP_DecryptInit_ex(EVP_CIPHER_CTX *ctx, const EVP_CIPHER *type, ENGINE *impl,
                       const unsigned char *key, const unsigned char *iv);

/* Since the process started (every thread); an initialisation without a cipher (the key and
 * the IV of an initialised context) counts in neither. */
void agent_cipher_counts(uint64_t *prefetched, uint64_t *as_given);

#endif
