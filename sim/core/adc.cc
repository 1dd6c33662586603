// SPDX-License-Identifier: Apache-2.0
// The air data computer's sample in C++ (the Python's sensors.AirData, used through it):
// calibrated airspeed (or the one a blocked pitot makes, given by the Python), pressure
// altitude and vertical speed read from JSBSim, each with its bias and noise drawn in the
// Python's order from the same stream, and AIR_DATA encoded. The Python keeps the counter.

#include "core.h"

namespace core {
namespace {

enum { CAS, PALT, HDOT, NN };

struct Adc {
    PyObject_HEAD
    Jsb jsb;
    void *node[NN];
    Normals *n;
    Biases bias;  // airspeed, altitude
    double noise_ias, noise_alt, noise_vs;
    Msg msg;  // AIR_DATA
    double last[3];
    PyObject *keep;
};

// frames(counter, cas) -> [(id, data)] of the next sample (cas None: the aircraft's), or None
// if a value is not finite (drawn all the same; last() has them)
PyObject *adc_frames(PyObject *self_, PyObject *const *args, Py_ssize_t nargs)
{
    Adc *s = reinterpret_cast<Adc *>(self_);
    if (s->keep == nullptr) {
        PyErr_SetString(PyExc_RuntimeError, "the Adc was not set up");
        return nullptr;
    }
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "frames(counter, cas)");
        return nullptr;
    }
    double cnt = PyFloat_AsDouble(args[0]);
    double cas = args[1] == Py_None ? s->jsb.get(s->node[CAS]) : PyFloat_AsDouble(args[1]);
    if (PyErr_Occurred())
        return nullptr;
    double palt = s->jsb.get(s->node[PALT]), hdot = s->jsb.get(s->node[HDOT]);
    double b, d;
    if (!biases_step(&s->bias, 0, s->n, &b) || !normals_next(s->n, &d))
        return nullptr;
    double ias = cas + b + s->noise_ias * d;
    s->last[0] = ias > 0.0 ? ias : 0.0;  // max(0.0, ias)
    if (!biases_step(&s->bias, 1, s->n, &b) || !normals_next(s->n, &d))
        return nullptr;
    s->last[1] = palt + b + s->noise_alt * d;
    if (!normals_next(s->n, &d))
        return nullptr;
    s->last[2] = hdot * 60.0 + s->noise_vs * d;
    double v[5] = {s->last[0], s->last[1], s->last[2], 1.0, cnt};
    PyObject *f = msg_frame(&s->msg, v);
    if (f == nullptr) {
        if (PyErr_Occurred())
            return nullptr;
        Py_RETURN_NONE;
    }
    return Py_BuildValue("[N]", f);
}

PyObject *adc_last(PyObject *self_, PyObject *)
{
    Adc *s = reinterpret_cast<Adc *>(self_);
    return Py_BuildValue("(ddd)", s->last[0], s->last[1], s->last[2]);
}

// Adc(lib_path, nodes(cas, palt, hdot), normals, biases((a, q, x) x 2), noise(ias, alt, vs),
//     message)
int adc_init(PyObject *self_, PyObject *args, PyObject *kw)
{
    Adc *s = reinterpret_cast<Adc *>(self_);
    const char *lib;
    PyObject *nodes, *normals, *biases, *noise, *msg;
    Py_CLEAR(s->keep);
    if ((kw != nullptr && PyDict_GET_SIZE(kw) != 0) ||
        !PyArg_ParseTuple(args, "sOOOOO", &lib, &nodes, &normals, &biases, &noise, &msg))
        return -1;
    if (!jsb_resolve(lib, &s->jsb))
        return -1;
    if (!is_normals(normals)) {
        PyErr_SetString(PyExc_TypeError, "normals: an imaworld._core.Normals expected");
        return -1;
    }
    if (!jsb_nodes(s->jsb, nodes, s->node, NN) || !biases_parse(biases, &s->bias, 2))
        return -1;
    double nz[3];
    if (!seq_doubles(noise, nz, 3, "noise (ias, alt, vs)") || !msg_parse(msg, &s->msg))
        return -1;
    if (s->msg.nsig != 5) {
        PyErr_SetString(PyExc_ValueError, "message: 5 signals expected");
        return -1;
    }
    s->noise_ias = nz[0];
    s->noise_alt = nz[1];
    s->noise_vs = nz[2];
    s->n = reinterpret_cast<Normals *>(normals);
    PyObject *held = PySequence_Tuple(nodes);  // a copy: the nodes stay what was given
    s->keep = held != nullptr ? Py_BuildValue("(ON)", normals, held) : nullptr;
    return s->keep != nullptr ? 0 : -1;
}

void adc_dealloc(PyObject *self_)
{
    dealloc_keeping(self_, reinterpret_cast<Adc *>(self_)->keep);
}

PyMethodDef adc_methods[] = {
    {"frames", fastcall(adc_frames),
     METH_FASTCALL, "frames(counter, cas) -> the next sample's frame, or None if not finite"},
    {"last", adc_last, METH_NOARGS, "last() -> the last sample's (ias, alt, vs)"},
    {nullptr, nullptr, 0, nullptr},
};

PyType_Slot adc_slots[] = {
    {Py_tp_doc, const_cast<char *>("The air data computer's sample (see sim/core/adc.cc).")},
    {Py_tp_new, reinterpret_cast<void *>(PyType_GenericNew)},
    {Py_tp_init, reinterpret_cast<void *>(adc_init)},
    {Py_tp_dealloc, reinterpret_cast<void *>(adc_dealloc)},
    {Py_tp_methods, adc_methods},
    {0, nullptr},
};

}  // namespace

PyType_Spec adc_spec = {"imaworld._core.Adc", sizeof(Adc), 0, Py_TPFLAGS_DEFAULT, adc_slots};

}  // namespace core
