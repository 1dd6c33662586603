/* SPDX-License-Identifier: Apache-2.0 */
/* OpenSSL's definitions, found at run time (agent__libcrypto.h). */
#include <dlfcn.h>
#include <stddef.h>

#include "agent__libcrypto.h"

void *agent_libcrypto_sym(const char *name)
{
    void *f = dlsym(RTLD_NEXT, name);
    if (!f) {
        void *lib = dlopen("libcrypto.so.3", RTLD_NOW | RTLD_NOLOAD);
        if (lib) {
            f = dlsym(lib, name);
            dlclose(lib); /* RTLD_NOLOAD took a reference: libcrypto stays loaded */
        }
    }
    return f;
}
