/* SPDX-License-Identifier: Apache-2.0 */
/* OpenSSL's own definitions of what the agent defines in its place (agent_hmac.c,
 * agent_cipher.c), found at run time: no OpenSSL headers, no link to libcrypto. */
#ifndef IMA_AGENT_LIBCRYPTO_H
#define IMA_AGENT_LIBCRYPTO_H

/* OpenSSL's `name`: the next definition after the executable's, else libcrypto's own (a
 * plugin loaded with RTLD_LOCAL keeps libcrypto out of the global scope); NULL if libcrypto
 * is not loaded or has no such function. */
void *agent_libcrypto_sym(const char *name);

#endif
