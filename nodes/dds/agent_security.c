/* SPDX-License-Identifier: Apache-2.0 */
/* DDS Security for the agent's participant: the properties of the OMG DDS Security builtin
 * plugins (authentication PKI-DH, access control, cryptography), pointing at the files the
 * launcher made for this run (python/ima/dds/security.py). The plugins are Cyclone's own
 * (Debian: libddsc0debian); CMake finds their directory (IMA_DDS_SECURITY_LIB_DIR). */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "agent__agent.h"

#ifndef IMA_DDS_SECURITY_LIB_DIR
#define IMA_DDS_SECURITY_LIB_DIR ""
#endif

/* Sets property `name` to "file:DIR/FILE" once the file is readable; -1 with a message. */
static int file_prop(agent_t *a, dds_qos_t *q, const char *name, const char *file)
{
    char path[PATH_MAX + 8];
    int n = snprintf(path, sizeof path, "file:%s/%s", a->o.security_dir, file);
    if (n < 0 || (size_t)n >= sizeof path) {
        fprintf(stderr, "ima-dds-node %s: --security path too long\n", a->node_name);
        return -1;
    }
    if (access(path + 5, R_OK) != 0) {
        fprintf(stderr, "ima-dds-node %s: DDS Security file %s: %s\n", a->node_name, path + 5,
                strerror(errno));
        return -1;
    }
    dds_qset_prop(q, name, path);
    return 0;
}

static int library_prop(agent_t *a, dds_qos_t *q, const char *plugin, const char *lib,
                        const char *fn)
{
    char key[64], path[PATH_MAX], init[48], fini[48];
    int n = snprintf(path, sizeof path, "%s/lib%s.so", IMA_DDS_SECURITY_LIB_DIR, lib);
    if (!*IMA_DDS_SECURITY_LIB_DIR || n < 0 || (size_t)n >= sizeof path ||
        access(path, R_OK) != 0) {
        fprintf(stderr,
                "ima-dds-node %s: Cyclone's DDS Security plugin lib%s.so is not installed "
                "(Debian package libddsc0debian; looked in '%s'): run with --dds-security off "
                "or install it\n",
                a->node_name, lib, IMA_DDS_SECURITY_LIB_DIR);
        return -1;
    }
    snprintf(init, sizeof init, "init_%s", fn);
    snprintf(fini, sizeof fini, "finalize_%s", fn);
    snprintf(key, sizeof key, "dds.sec.%s.library.path", plugin);
    dds_qset_prop(q, key, path);
    snprintf(key, sizeof key, "dds.sec.%s.library.init", plugin);
    dds_qset_prop(q, key, init);
    snprintf(key, sizeof key, "dds.sec.%s.library.finalize", plugin);
    dds_qset_prop(q, key, fini);
    return 0;
}

dds_qos_t *agent_security_qos(agent_t *a)
{
    dds_qos_t *q = dds_create_qos();
    if (!a->o.security_dir)
        return q;
    char cert[32], key[32];
    snprintf(cert, sizeof cert, "node%u.pem", a->o.node);
    snprintf(key, sizeof key, "node%u.key", a->o.node);
    if (library_prop(a, q, "auth", "dds_security_auth", "authentication") != 0 ||
        library_prop(a, q, "access", "dds_security_ac", "access_control") != 0 ||
        library_prop(a, q, "crypto", "dds_security_crypto", "crypto") != 0 ||
        file_prop(a, q, "dds.sec.auth.identity_ca", "identity_ca.pem") != 0 ||
        file_prop(a, q, "dds.sec.auth.identity_certificate", cert) != 0 ||
        file_prop(a, q, "dds.sec.auth.private_key", key) != 0 ||
        file_prop(a, q, "dds.sec.access.permissions_ca", "permissions_ca.pem") != 0 ||
        file_prop(a, q, "dds.sec.access.governance", "governance.p7s") != 0 ||
        file_prop(a, q, "dds.sec.access.permissions", "permissions.p7s") != 0) {
        dds_delete_qos(q);
        return NULL;
    }
    return q;
}
