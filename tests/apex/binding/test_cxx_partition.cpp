/* SPDX-License-Identifier: Apache-2.0 */
/* A C++ partition using the APEX headers as they are (they declare everything extern "C"):
 * a periodic producer reads the C partition's time from a sampling port, hands an item to an
 * aperiodic consumer through a buffer and displays a note on a blackboard; the consumer
 * reports what it got. Built with the project's warnings and -Werror, as C++17. */
#include <array>
#include <cstdarg>
#include <cstdio>
#include <cstring>

#include "ARINC653.h"

namespace {

constexpr SYSTEM_TIME_TYPE operator""_ms(unsigned long long v)
{
    return static_cast<SYSTEM_TIME_TYPE>(v) * 1000000LL;
}

static_assert(sizeof(SYSTEM_TIME_TYPE) == sizeof(long long), "APEX_LONG_INTEGER is long long");

__attribute__((format(printf, 1, 2))) void report(const char *fmt, ...)
{
    std::array<char, MAX_ERROR_MESSAGE_SIZE + 1> text{};
    va_list ap;
    va_start(ap, fmt);
    int n = std::vsnprintf(text.data(), text.size(), fmt, ap);
    va_end(ap);
    if (n < 0)
        return;
    RETURN_CODE_TYPE rc;
    REPORT_APPLICATION_MESSAGE(reinterpret_cast<MESSAGE_ADDR_TYPE>(text.data()),
                               n > MAX_ERROR_MESSAGE_SIZE ? MAX_ERROR_MESSAGE_SIZE : n, &rc);
}

enum class Validity { invalid, valid };

const char *name(Validity v) { return v == Validity::valid ? "VALID" : "INVALID"; }

struct Item {
    int sequence;
    long long sent_at;
    long long c_time; /* what the C partition last wrote */
};

/* A buffer carrying values of one trivially copyable type. */
template <typename T> class Typed_buffer {
public:
    bool create(const char *buffer_name, MESSAGE_RANGE_TYPE capacity)
    {
        RETURN_CODE_TYPE rc;
        CREATE_BUFFER(buffer_name, sizeof(T), capacity, FIFO, &id_, &rc);
        return rc == NO_ERROR;
    }
    RETURN_CODE_TYPE send(const T &value) const
    {
        RETURN_CODE_TYPE rc;
        auto *bytes = reinterpret_cast<MESSAGE_ADDR_TYPE>(const_cast<T *>(&value));
        SEND_BUFFER(id_, bytes, sizeof(T), 0, &rc);
        return rc;
    }
    RETURN_CODE_TYPE receive(T &value, SYSTEM_TIME_TYPE time_out) const
    {
        MESSAGE_SIZE_TYPE length = 0;
        RETURN_CODE_TYPE rc;
        RECEIVE_BUFFER(id_, time_out, reinterpret_cast<MESSAGE_ADDR_TYPE>(&value), &length, &rc);
        const bool whole = length == static_cast<MESSAGE_SIZE_TYPE>(sizeof(T));
        return rc == NO_ERROR && !whole ? INVALID_CONFIG : rc;
    }

private:
    BUFFER_ID_TYPE id_ = 0;
};

Typed_buffer<Item> items;
BLACKBOARD_ID_TYPE notes = 0;
SAMPLING_PORT_ID_TYPE c_time_port = 0;

void producer()
{
    for (int sequence = 0;; ++sequence) {
        RETURN_CODE_TYPE rc;
        long long now = 0;
        GET_TIME(&now, &rc);
        long long c_time = -1;
        MESSAGE_SIZE_TYPE length = 0;
        VALIDITY_TYPE validity = INVALID;
        READ_SAMPLING_MESSAGE(c_time_port, reinterpret_cast<MESSAGE_ADDR_TYPE>(&c_time), &length,
                              &validity, &rc);
        const Validity v = validity == VALID ? Validity::valid : Validity::invalid;
        report("producer read %lld ns from C (%s, rc %d)", c_time, name(v), static_cast<int>(rc));
        if (items.send(Item{sequence, now, c_time}) != NO_ERROR)
            report("producer could not send %d", sequence);
        std::array<char, 32> note{};
        const int n = std::snprintf(note.data(), note.size(), "note %d", sequence);
        DISPLAY_BLACKBOARD(notes, reinterpret_cast<MESSAGE_ADDR_TYPE>(note.data()), n, &rc);
        PERIODIC_WAIT(&rc);
    }
}

void consumer()
{
    for (;;) {
        Item item{};
        if (items.receive(item, INFINITE_TIME_VALUE) != NO_ERROR) {
            report("consumer: receive failed");
            return;
        }
        std::array<char, 32> note{};
        MESSAGE_SIZE_TYPE length = 0;
        RETURN_CODE_TYPE rc;
        READ_BLACKBOARD(notes, 0, reinterpret_cast<MESSAGE_ADDR_TYPE>(note.data()), &length, &rc);
        report("consumer got item %d sent at %lld ns, C time %lld ns, %.*s", item.sequence,
               item.sent_at, item.c_time, static_cast<int>(length), note.data());
    }
}

PROCESS_ID_TYPE create(const char *process_name, void (*entry)(), SYSTEM_TIME_TYPE period,
                       PRIORITY_TYPE priority)
{
    PROCESS_ATTRIBUTE_TYPE attr{};
    attr.PERIOD = period;
    attr.TIME_CAPACITY = period == INFINITE_TIME_VALUE ? INFINITE_TIME_VALUE : period;
    attr.ENTRY_POINT = reinterpret_cast<SYSTEM_ADDRESS_TYPE>(entry);
    attr.STACK_SIZE = 65536;
    attr.BASE_PRIORITY = priority;
    attr.DEADLINE = SOFT;
    /* A NAME_TYPE needs no NUL. */
    std::memcpy(attr.NAME, process_name, strnlen(process_name, sizeof attr.NAME));
    PROCESS_ID_TYPE id = NULL_PROCESS_ID;
    RETURN_CODE_TYPE rc;
    CREATE_PROCESS(&attr, &id, &rc);
    if (rc == NO_ERROR)
        START(id, &rc);
    if (rc != NO_ERROR)
        report("SETUP %s: rc %d", process_name, static_cast<int>(rc));
    return id;
}

} // namespace

int main()
{
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT("C_TIME", sizeof(long long), DESTINATION, 25_ms, &c_time_port, &rc);
    if (rc != NO_ERROR || !items.create("ITEMS", 4))
        return 1;
    CREATE_BLACKBOARD("NOTES", 32, &notes, &rc);
    if (rc != NO_ERROR)
        return 1;
    const auto processes = std::array{
        create("producer", producer, 20_ms, 20),
        create("consumer", consumer, INFINITE_TIME_VALUE, 10),
    };
    report("C++ partition ready with %zu processes", processes.size());
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
