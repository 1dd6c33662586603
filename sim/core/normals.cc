// SPDX-License-Identifier: Apache-2.0
// Normals: a sensor's stream of standard normal draws, one per call, taken from blocks that a
// Python callable returns (sensors.normal_stream hands it numpy's PCG64 blocks): the same
// draws in the same order whether the Python or the C++ takes them.

#include "core.h"

#include <cstdlib>

namespace core {
namespace {

PyObject *normals_call(PyObject *self_, PyObject *args, PyObject *kw)
{
    if (PyTuple_GET_SIZE(args) != 0 || (kw != nullptr && PyDict_GET_SIZE(kw) != 0)) {
        PyErr_SetString(PyExc_TypeError, "a Normals takes no arguments");
        return nullptr;
    }
    double x;
    if (!normals_next(reinterpret_cast<Normals *>(self_), &x))
        return nullptr;
    return PyFloat_FromDouble(x);
}

int normals_init(PyObject *self_, PyObject *args, PyObject *kw)
{
    Normals *s = reinterpret_cast<Normals *>(self_);
    PyObject *draw;
    if ((kw != nullptr && PyDict_GET_SIZE(kw) != 0) || !PyArg_ParseTuple(args, "O", &draw))
        return -1;
    if (!PyCallable_Check(draw)) {
        PyErr_SetString(PyExc_TypeError, "Normals(draw): draw() returns the next block");
        return -1;
    }
    Py_INCREF(draw);
    Py_XSETREF(s->draw, draw);
    s->i = s->n = 0;
    return 0;
}

void normals_dealloc(PyObject *self_)
{
    Normals *s = reinterpret_cast<Normals *>(self_);
    free(s->block);
    dealloc_keeping(self_, s->draw);
}

PyType_Slot normals_slots[] = {
    {Py_tp_doc, const_cast<char *>("Normals(draw): n() -> the next draw; draw() gives a block.")},
    {Py_tp_new, reinterpret_cast<void *>(PyType_GenericNew)},
    {Py_tp_init, reinterpret_cast<void *>(normals_init)},
    {Py_tp_dealloc, reinterpret_cast<void *>(normals_dealloc)},
    {Py_tp_call, reinterpret_cast<void *>(normals_call)},
    {0, nullptr},
};

}  // namespace

bool is_normals(PyObject *o)
{
    return Py_TYPE(o)->tp_dealloc == normals_dealloc;
}

bool normals_next(Normals *s, double *x)
{
    if (s->i == s->n) {
        if (s->draw == nullptr) {
            PyErr_SetString(PyExc_RuntimeError, "the Normals was not set up");
            return false;
        }
        PyObject *got = PyObject_CallNoArgs(s->draw);
        if (got == nullptr)
            return false;
        PyObject *fast = PySequence_Fast(got, "a block of draws");
        Py_DECREF(got);
        if (fast == nullptr)
            return false;
        Py_ssize_t n = PySequence_Fast_GET_SIZE(fast);
        double *block = n > 0 ? static_cast<double *>(malloc(sizeof(double) * n)) : nullptr;
        if (block == nullptr) {
            Py_DECREF(fast);
            PyErr_SetString(n > 0 ? PyExc_MemoryError : PyExc_ValueError,
                            n > 0 ? "no memory for a block of draws" : "an empty block of draws");
            return false;
        }
        for (Py_ssize_t k = 0; k < n; k++) {
            block[k] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(fast, k));
            if (block[k] == -1.0 && PyErr_Occurred()) {
                free(block);
                Py_DECREF(fast);
                return false;
            }
        }
        Py_DECREF(fast);
        free(s->block);
        s->block = block;
        s->n = n;
        s->i = 0;
    }
    *x = s->block[s->i++];
    return true;
}

bool biases_parse(PyObject *seq, Biases *b, int n)
{
    PyObject *fast = PySequence_Fast(seq, "biases");
    if (fast == nullptr)
        return false;
    bool ok = n <= MAX_BIASES && PySequence_Fast_GET_SIZE(fast) == n;
    for (int k = 0; ok && k < n; k++) {
        double aqx[3];
        ok = seq_doubles(PySequence_Fast_GET_ITEM(fast, k), aqx, 3, "a bias (a, q, x)");
        if (ok) {
            b->a[k] = aqx[0];
            b->q[k] = aqx[1];
            b->x[k] = aqx[2];
        }
    }
    Py_DECREF(fast);
    if (!ok && !PyErr_Occurred())
        PyErr_Format(PyExc_ValueError, "biases: %d (a, q, x) expected", n);
    return ok;
}

bool biases_step(Biases *b, int k, Normals *n, double *out)
{
    double d;
    if (!normals_next(n, &d))
        return false;
    b->x[k] = b->a[k] * b->x[k] + b->q[k] * d;
    *out = b->x[k];
    return true;
}

PyType_Spec normals_spec = {"imaworld._core.Normals", sizeof(Normals), 0, Py_TPFLAGS_DEFAULT,
                            normals_slots};

}  // namespace core
