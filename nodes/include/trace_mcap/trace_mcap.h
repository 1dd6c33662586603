/* SPDX-License-Identifier: Apache-2.0 */
/* Trace lines to MCAP message records, for the recorder (python/ima/recording/fast.py, through
 * ctypes on libima_trace_mcap.so).
 *
 * The recorder turns every line of the bus's trace (can.jsonl) and of each SKE's trace
 * (nodeK.jsonl) into MCAP messages: a CAN frame becomes a /can/frames message and a message of
 * its decoded signals; an SKE line goes as it is to its node's schedule, hm or events topic;
 * a flight data recorder's frame record becomes its JSON (tm_fdr). That is most of a
 * recording's messages. This code does, for the lines in the form the bus
 * and the SKE write, exactly what the recorder's Python does (python/ima/recording/topics.py),
 * byte for byte; any other line (a cut or garbled one, an event, a frame of an id it has not
 * been told about) it hands back to the Python, which handles it and tells it what it learned
 * (a channel, a frame's added fields). */
#ifndef TRACE_MCAP_H
#define TRACE_MCAP_H

#include <stddef.h>
#include <stdint.h>

enum { TM_CAN = 1, TM_SKE = 2, TM_FDR = 3 };               /* which trace a converter reads */
enum { TM_DONE = 0, TM_PYTHON = 1, TM_FULL = 2, TM_NOMEM = -1 }; /* tm_convert's answers */
enum { TM_CAN_FRAMES = 0, TM_SKE_SCHEDULE = 0, TM_SKE_HM = 1, TM_SKE_OTHER = 2,
       TM_FDR_RECORDS = 0 };

typedef struct tm_conv tm_conv_t;

typedef struct {
    size_t consumed;    /* bytes of the text handled (whole lines) */
    uint64_t lines;     /* lines handled */
    uint32_t part;      /* TM_FULL: messages of the line at `consumed` already out (0 or 1) */
    const uint8_t *out; /* the message records, valid until the next call */
    size_t out_len;
} tm_result_t;

tm_conv_t *tm_new(int kind);
void tm_free(tm_conv_t *c);

/* A topic's MCAP channel: TM_CAN_FRAMES, an SKE trace's TM_SKE_*, or a flight data
 * recording's TM_FDR_RECORDS. 0 = none yet. */
void tm_set_channel(tm_conv_t *c, int which, uint16_t cid);

/* A DBC message (CAN): its length, the channel of its signals' topic (0 = none yet, then
 * again to set it), and whether this code decodes it (else its frames are the Python's). Its
 * signals follow with tm_can_signal, in the DBC's order (little-endian, at most 53 bits):
 * `integer` when the Python decodes the signal with integer arithmetic (whole scale and
 * offset), `key` its JSON key with the colon ("NAME":). A message registered again keeps its
 * signals. */
int tm_can_message(tm_conv_t *c, uint32_t id, uint32_t length, uint16_t sig_cid,
                   int supported);
int tm_can_signal(tm_conv_t *c, uint32_t id, uint32_t start, uint32_t length, int is_signed,
                  int integer, double scale, double offset, const char *key);

/* What a can_tx frame of this id and format adds to its line (,"error":false,"name":...). */
int tm_can_key(tm_conv_t *c, uint32_t id, int ext, const char *extra, size_t n);

/* Converts the lines of text[0..len) (each ending in '\n', the first numbered seq) into
 * message records, the first at offset `base` of the chunk being built. It stops:
 *  TM_DONE   every line is out;
 *  TM_PYTHON before the line at r->consumed, which it does not handle;
 *  TM_FULL   once the records reach `room` bytes (the chunk is full): r->part messages of the
 *            line at r->consumed are out, the caller resumes with skip = r->part.
 * The index entries (log time, offset) of the call's records: tm_channels lists their
 * channels in the order of each one's first record, tm_entries gives a channel's. */
int tm_convert(tm_conv_t *c, const uint8_t *text, size_t len, uint64_t seq, uint64_t base,
               uint64_t room, uint32_t skip, tm_result_t *r);
size_t tm_channels(const tm_conv_t *c, const uint16_t **cids);
size_t tm_entries(const tm_conv_t *c, uint16_t cid, const uint64_t **pairs);

/* How many lines end in text[0..len): its '\n' bytes (the recorder numbers a trace's lines by
 * them; Python's bytes.count scans a byte at a time, glibc's memchr a vector at a time). */
uint64_t tm_count_lines(const uint8_t *text, size_t len);

/* A flight data recorder file's records (TM_FDR converter; partitions/fdr/fdr.h: fixed
 * 320-byte records, each a header, a body and a CRC-32): of the file's `n` whole records at
 * `data`, those from record `from` on, the first good one numbered `seq`, as messages of the
 * node's fdr topic (TM_FDR_RECORDS), each what the recorder's Python writes
 * (python/ima/recording/write.py: the JSON of ima.fdr.records' decoding, with its "kind"). A
 * torn frame record (bad magic, version, length or CRC) or one of no kind is skipped.
 * `r->consumed` is the record reached, `r->lines` the good records out. It hands back
 * (TM_PYTHON) the record at `consumed` if it is a start or a health-monitor record (the Python
 * judges whether it is torn) or while it has no channel; TM_FULL once `room` bytes are out
 * (after at least one record). TM_NOMEM, nothing done, on a converter of another kind. */
int tm_fdr(tm_conv_t *c, const uint8_t *data, size_t n, size_t from, uint64_t seq,
           uint64_t base, uint64_t room, tm_result_t *r);

/* A finite double as orjson writes it (shortest round trip: 12.34, 1e-7, 1e+16); its length
 * (at most 32 bytes, no terminating NUL), 0 for a NaN or an infinity. */
size_t tm_format_double(double x, char *buf);

#endif
