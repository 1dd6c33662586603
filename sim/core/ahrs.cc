// SPDX-License-Identifier: Apache-2.0
// The AHRS's sample in C++ (the Python's sensors.Ahrs, used through it): the aircraft's
// attitude, rates and specific force read from JSBSim, each with its Gauss-Markov bias and its
// noise drawn in the Python's order from the same stream, and the three frames encoded. The
// Python keeps the counter and the faults: with a fault in force it takes the values only.

#include "core.h"

#include <cmath>

namespace core {
namespace {

constexpr double DEG = 180.0 / M_PI;

// Gauss-Markov biases, in the Python's order: roll, pitch, heading, p, q, r, ax, ay, az.
constexpr int NV = 9;

struct Ahrs {
    PyObject_HEAD
    Jsb jsb;
    void *node[NV];  // phi, theta, psi (deg), p, q, r (rad/s), ax, ay, az (g)
    Normals *n;
    Biases bias;  // roll, pitch, heading, p, q, r, ax, ay, az
    double noise_att, noise_hdg, noise_rate, noise_accel;
    Msg msg[3];  // AHRS_ATT, AHRS_RATE, AHRS_ACCEL
    double last[NV];
    bool has_last;
    PyObject *keep;  // (normals, nodes): what the pointers above point into
};

// One sample's values, as sensors.Ahrs.sample computes them, into s->last.
bool draw(Ahrs *s)
{
    double in[NV], b, d;
    for (int k = 0; k < NV; k++)
        in[k] = s->jsb.get(s->node[k]);
    double *v = s->last;
    if (!biases_step(&s->bias, 0, s->n, &b) || !normals_next(s->n, &d))
        return false;
    double roll = in[0] + b + s->noise_att * d;
    if (roll > 180.0)
        roll -= 360.0;
    else if (roll < -180.0)
        roll += 360.0;
    v[0] = roll;
    if (!biases_step(&s->bias, 1, s->n, &b) || !normals_next(s->n, &d))
        return false;
    v[1] = in[1] + b + s->noise_att * d;
    if (!biases_step(&s->bias, 2, s->n, &b) || !normals_next(s->n, &d))
        return false;
    double hdg = py_mod(in[2] + b + s->noise_hdg * d, 360.0);
    v[2] = hdg >= 359.995 ? 0.0 : hdg;
    for (int k = 3; k < 6; k++) {
        if (!biases_step(&s->bias, k, s->n, &b) || !normals_next(s->n, &d))
            return false;
        v[k] = in[k] * DEG + b + s->noise_rate * d;
    }
    for (int k = 6; k < 9; k++) {
        if (!biases_step(&s->bias, k, s->n, &b) || !normals_next(s->n, &d))
            return false;
        v[k] = in[k] + b + s->noise_accel * d;
    }
    s->has_last = true;
    return true;
}

PyObject *last_tuple(const Ahrs *s)
{
    PyObject *t = PyTuple_New(NV);
    for (int k = 0; t != nullptr && k < NV; k++) {
        PyObject *f = PyFloat_FromDouble(s->last[k]);
        if (f == nullptr) {
            Py_CLEAR(t);
            break;
        }
        PyTuple_SET_ITEM(t, k, f);
    }
    return t;
}

bool ready(const Ahrs *s)
{
    if (s->keep == nullptr)
        PyErr_SetString(PyExc_RuntimeError, "the Ahrs was not set up");
    return s->keep != nullptr;
}

// vals() -> the next sample's 9 values (drawn)
PyObject *ahrs_vals(PyObject *self_, PyObject *)
{
    Ahrs *s = reinterpret_cast<Ahrs *>(self_);
    if (!ready(s) || !draw(s))
        return nullptr;
    return last_tuple(s);
}

// frames(counter) -> [(id, data)] x 3 of the next sample, or None if a value is not finite
// (drawn all the same; last() has them)
PyObject *ahrs_frames(PyObject *self_, PyObject *arg)
{
    Ahrs *s = reinterpret_cast<Ahrs *>(self_);
    double cnt = PyFloat_AsDouble(arg);
    if ((cnt == -1.0 && PyErr_Occurred()) || !ready(s) || !draw(s))
        return nullptr;
    PyObject *out = PyList_New(3);
    if (out == nullptr)
        return nullptr;
    for (int m = 0; m < 3; m++) {
        double v[5] = {s->last[3 * m], s->last[3 * m + 1], s->last[3 * m + 2], 3.0, cnt};
        PyObject *f = msg_frame(&s->msg[m], v);
        if (f == nullptr) {
            Py_DECREF(out);
            if (PyErr_Occurred())
                return nullptr;
            Py_RETURN_NONE;
        }
        PyList_SET_ITEM(out, m, f);
    }
    return out;
}

// last() -> the last sample's values, or None before the first
PyObject *ahrs_last(PyObject *self_, PyObject *)
{
    Ahrs *s = reinterpret_cast<Ahrs *>(self_);
    if (!s->has_last)
        Py_RETURN_NONE;
    return last_tuple(s);
}

// Ahrs(lib_path, nodes(9), normals, biases((a, q, x) x 9), noise(att, hdg, rate, accel),
//      messages(3 specs: see msg_parse))
int ahrs_init(PyObject *self_, PyObject *args, PyObject *kw)
{
    Ahrs *s = reinterpret_cast<Ahrs *>(self_);
    const char *lib;
    PyObject *nodes, *normals, *biases, *noise, *msgs;
    Py_CLEAR(s->keep);
    if ((kw != nullptr && PyDict_GET_SIZE(kw) != 0) ||
        !PyArg_ParseTuple(args, "sOOOOO", &lib, &nodes, &normals, &biases, &noise, &msgs))
        return -1;
    if (!jsb_resolve(lib, &s->jsb))
        return -1;
    if (!is_normals(normals)) {
        PyErr_SetString(PyExc_TypeError, "normals: an imaworld._core.Normals expected");
        return -1;
    }
    if (!jsb_nodes(s->jsb, nodes, s->node, NV) || !biases_parse(biases, &s->bias, NV))
        return -1;
    double nz[4];
    if (!seq_doubles(noise, nz, 4, "noise (att, hdg, rate, accel)"))
        return -1;
    s->noise_att = nz[0];
    s->noise_hdg = nz[1];
    s->noise_rate = nz[2];
    s->noise_accel = nz[3];
    PyObject *fm = PySequence_Fast(msgs, "messages");
    if (fm == nullptr)
        return -1;
    bool ok = PySequence_Fast_GET_SIZE(fm) == 3;
    for (int m = 0; ok && m < 3; m++)
        ok = msg_parse(PySequence_Fast_GET_ITEM(fm, m), &s->msg[m]) && s->msg[m].nsig == 5;
    Py_DECREF(fm);
    if (!ok) {
        if (!PyErr_Occurred())
            PyErr_SetString(PyExc_ValueError, "messages: 3 of 5 signals expected");
        return -1;
    }
    s->n = reinterpret_cast<Normals *>(normals);
    s->has_last = false;
    PyObject *held = PySequence_Tuple(nodes);  // a copy: the nodes stay what was given
    s->keep = held != nullptr ? Py_BuildValue("(ON)", normals, held) : nullptr;
    return s->keep != nullptr ? 0 : -1;
}

void ahrs_dealloc(PyObject *self_)
{
    dealloc_keeping(self_, reinterpret_cast<Ahrs *>(self_)->keep);
}

PyMethodDef ahrs_methods[] = {
    {"vals", ahrs_vals, METH_NOARGS, "vals() -> the next sample's 9 values"},
    {"frames", ahrs_frames, METH_O,
     "frames(counter) -> the next sample's 3 frames, or None if a value is not finite"},
    {"last", ahrs_last, METH_NOARGS, "last() -> the last sample's values, or None"},
    {nullptr, nullptr, 0, nullptr},
};

PyType_Slot ahrs_slots[] = {
    {Py_tp_doc, const_cast<char *>("The AHRS's sample (see sim/core/ahrs.cc).")},
    {Py_tp_new, reinterpret_cast<void *>(PyType_GenericNew)},
    {Py_tp_init, reinterpret_cast<void *>(ahrs_init)},
    {Py_tp_dealloc, reinterpret_cast<void *>(ahrs_dealloc)},
    {Py_tp_methods, ahrs_methods},
    {0, nullptr},
};

}  // namespace

PyType_Spec ahrs_spec = {"imaworld._core.Ahrs", sizeof(Ahrs), 0, Py_TPFLAGS_DEFAULT, ahrs_slots};

}  // namespace core
