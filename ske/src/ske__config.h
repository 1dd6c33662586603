/* SPDX-License-Identifier: Apache-2.0 */
/* The module loader's private interface: the loader's state, passed to every file of the
 * loader, and the XML helpers they share (diagnostics, attributes, partition references). */
#ifndef SKE__CONFIG_H
#define SKE__CONFIG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <libxml/tree.h>

#include "ske/config.h"

#define SKE_EXT_NS "urn:ima-testbed:arinc653-linux:1"
#define SKE_SCHEMA_FILE "ima653_module.xsd"

#define SKE_MODULE_MAX_BYTES (8u << 20) /* a module file beyond it is refused */

typedef struct {
    ske_module_cfg_t *m;
    ske_diag_t *diag;
    const ske_load_opts_t *opts;
    bool failed;
    char *text; /* the module file, to find where start tags begin */
    size_t text_len;
    bool too_big; /* beyond SKE_MODULE_MAX_BYTES: not read further */
    size_t *line_at; /* offset of each line's first character, 1-based */
    int n_lines;
} ske_loader_t;

/* ---- config_xml.c: XML helpers -------------------------------------------------------- */

void ske__diag_set(ske_diag_t *d, const char *file, int line, const char *element, const char *rule,
                   const char *fmt, ...) __attribute__((format(printf, 6, 7)));
/* Fails the load at `node` unless an earlier rule already failed (the first error wins). */
void ske__fail(ske_loader_t *L, const xmlNode *node, const char *rule, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* The line where the element's start tag begins. */
int ske__line_of(const ske_loader_t *L, const xmlNode *node);
/* Reads the module file to find where start tags begin (line_of). */
void ske__index_lines(ske_loader_t *L);
/* Whether n is the element `name`, in the extension namespace if `ext`, in none otherwise. */
bool ske__is_elem(const xmlNode *n, const char *name, bool ext);
/* Attribute value copied into buf; false when absent. */
bool ske__attr(const xmlNode *n, const char *name, char *buf, size_t len);
/* The typed attributes: false when absent or invalid (the load failed then, or if required). */
bool ske__attr_seconds(ske_loader_t *L, const xmlNode *n, const char *name, int64_t *ns,
                       bool required);
bool ske__attr_u64(ske_loader_t *L, const xmlNode *n, const char *name, uint64_t *v, uint64_t max,
                   bool required);
bool ske__attr_bool(const xmlNode *n, const char *name, bool dflt);
bool ske__attr_name(ske_loader_t *L, const xmlNode *n, const char *name, char *out);
/* A partition reference: PartitionIdentifier and PartitionName must name the same one. Its
 * index, or -1 (the load failed). */
int ske__partition_ref(ske_loader_t *L, const xmlNode *n);
/* libxml2's error callback while parsing: the load fails with its message. */
void ske__parse_error(void *ctx, xmlErrorPtr err);
/* libxml2's generic error callback: quiet (errors come through the structured one). */
void ske__xml_silent(void *ctx, const char *msg, ...);
/* Validates the document against the module schema; SKE_OK or a status (diagnostic set). */
int ske__validate_schema(ske_loader_t *L, xmlDocPtr doc);

/* ---- config_schedule.c: module schedules ---------------------------------------------- */

void ske__load_schedule(ske_loader_t *L, const xmlNode *n);
/* Once every schedule is read: windows sorted and checked, the initial schedule. */
void ske__check_windows(ske_loader_t *L, const xmlNode *root);

/* ---- config_channels.c: channels ------------------------------------------------------ */

void ske__load_channel(ske_loader_t *L, const xmlNode *n);

/* ---- config_hm.c: health-monitoring tables -------------------------------------------- */

void ske__load_system_hm(ske_loader_t *L, const xmlNode *n);
void ske__load_module_hm(ske_loader_t *L, const xmlNode *n);
/* seen[i]: partition i already has its table. */
void ske__load_partition_hm(ske_loader_t *L, const xmlNode *n, bool seen[]);

#endif /* SKE__CONFIG_H */
