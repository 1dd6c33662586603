// SPDX-License-Identifier: Apache-2.0
// CAN frames encoded as ima.canbus.codec encodes them (little-endian integer signals): raw =
// round((value - offset) / scale), half to even, saturated at the signal's range.

#include "core.h"

#include <cmath>

namespace core {

bool msg_parse(PyObject *spec, Msg *m)
{
    // spec: (frame_id, length, ((start, length, signed, scale, offset), ...))
    PyObject *sigs;
    unsigned long id;
    int length;
    if (!PyArg_ParseTuple(spec, "kiO", &id, &length, &sigs))
        return false;
    PyObject *fast = PySequence_Fast(sigs, "signals");
    if (fast == nullptr)
        return false;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(fast);
    if (length < 1 || length > 8 || n < 1 || n > MSG_MAX_SIGNALS) {
        Py_DECREF(fast);
        PyErr_SetString(PyExc_ValueError, "a message of 1 to 8 bytes and 1 to 16 signals");
        return false;
    }
    m->id = static_cast<uint32_t>(id);
    m->length = length;
    m->nsig = static_cast<int>(n);
    for (Py_ssize_t i = 0; i < n; i++) {
        Sig &s = m->sig[i];
        int is_signed;
        if (!PyArg_ParseTuple(PySequence_Fast_GET_ITEM(fast, i), "iipdd", &s.start, &s.length,
                              &is_signed, &s.scale, &s.offset)) {
            Py_DECREF(fast);
            return false;
        }
        if (s.length < 1 || s.length > 32 || s.start < 0 || s.start + s.length > 8 * length) {
            Py_DECREF(fast);
            PyErr_SetString(PyExc_ValueError, "a signal of 1 to 32 bits within the message");
            return false;
        }
        s.is_signed = is_signed != 0;
    }
    Py_DECREF(fast);
    return true;
}

bool msg_encode(const Msg *m, const double *v, uint8_t out[8])
{
    uint64_t x = 0;
    for (int i = 0; i < m->nsig; i++) {
        const Sig &s = m->sig[i];
        double raw = std::rint((v[i] - s.offset) / s.scale);
        if (!std::isfinite(raw))
            return false;  // the Python's round() raises: let it
        int64_t lo = s.is_signed ? -(int64_t{1} << (s.length - 1)) : 0;
        int64_t hi = s.is_signed ? (int64_t{1} << (s.length - 1)) - 1 : (int64_t{1} << s.length) - 1;
        int64_t r = raw < static_cast<double>(lo)   ? lo
                    : raw > static_cast<double>(hi) ? hi
                                                    : static_cast<int64_t>(raw);
        uint64_t mask = (uint64_t{1} << s.length) - 1;
        x |= (static_cast<uint64_t>(r) & mask) << s.start;
    }
    for (int k = 0; k < m->length; k++)
        out[k] = static_cast<uint8_t>(x >> (8 * k));
    return true;
}

PyObject *msg_frame(const Msg *m, const double *v)
{
    uint8_t data[8];
    if (!msg_encode(m, v, data))
        return nullptr;
    return Py_BuildValue("(ky#)", static_cast<unsigned long>(m->id),
                         reinterpret_cast<const char *>(data), static_cast<Py_ssize_t>(m->length));
}

}  // namespace core
