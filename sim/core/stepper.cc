// SPDX-License-Identifier: Apache-2.0
// The world's physics steps in C++ (the Stepper of the Python module imaworld._core, used by
// sim/imaworld/stepper.py): the smart actuators' rate limits, the controls handed to JSBSim,
// JSBSim's step, and the watch on the crash limits, for every step up to an instant, in one
// call. It drives the JSBSim of the `jsbsim` wheel, the very object the Python holds, through
// the C++ functions that wheel's _jsbsim.so exports, so a step computes what the Python's
// World.advance computes, to the bit.
//
// It leaves to the Python what happens rarely: it returns when the actuators need a target
// (the Python's Actuators._target, at an instant the Python names), and after any step whose
// state is near a crash limit or near the ground (the Python then judges that step itself).

#include "core.h"

#include <cmath>
#include <exception>

namespace core {
namespace {

struct Stepper {
    PyObject_HEAD
    Jsb jsb;
    void *fdm;
    void *ctl[4];  // elevator, aileron, rudder (negated: see fdm.py), throttle commands
    void *agl, *phi, *cas, *nz;
    double lo[4], hi[4], move[4];
    int64_t hz;
    int64_t n;  // physics steps done
    double max_roll, max_cas, max_load, near_ground_ft;
    PyObject *keep;  // the Python objects owning what the pointers above point at
};

// Stepper(lib_path, fdm, controls, agl, phi, cas, nz, lo, hi, moves, hz,
//         max_roll_deg, max_cas_kt, max_load_g, near_ground_ft)
int stepper_init(PyObject *self_, PyObject *args, PyObject *kw)
{
    Stepper *s = reinterpret_cast<Stepper *>(self_);
    const char *lib;
    PyObject *fdm, *ctl, *agl, *phi, *cas, *nz, *lo, *hi, *moves;
    long long hz;
    Py_CLEAR(s->keep);  // set again only once all is set: until then run() refuses
    if (kw != nullptr && PyDict_GET_SIZE(kw) != 0) {
        PyErr_SetString(PyExc_TypeError, "Stepper takes no keyword arguments");
        return -1;
    }
    if (!PyArg_ParseTuple(args, "sOOOOOOOOOLdddd", &lib, &fdm, &ctl, &agl, &phi, &cas, &nz,
                          &lo, &hi, &moves, &hz, &s->max_roll, &s->max_cas, &s->max_load,
                          &s->near_ground_ft))
        return -1;
    if (hz <= 0) {
        PyErr_SetString(PyExc_ValueError, "the physics rate must be > 0");
        return -1;
    }
    if (!jsb_resolve(lib, &s->jsb))
        return -1;
    s->fdm = jsb_fdm(s->jsb, fdm);
    if (s->fdm == nullptr)
        return -1;
    if (!jsb_nodes(s->jsb, ctl, s->ctl, 4))
        return -1;
    const Jsb &j = s->jsb;
    if (!(s->agl = jsb_node(j, agl)) || !(s->phi = jsb_node(j, phi)) ||
        !(s->cas = jsb_node(j, cas)) || !(s->nz = jsb_node(j, nz)))
        return -1;
    if (!seq_doubles(lo, s->lo, 4, "lo") || !seq_doubles(hi, s->hi, 4, "hi") ||
        !seq_doubles(moves, s->move, 4, "moves"))
        return -1;
    s->hz = hz;
    s->n = 0;
    PyObject *held = PySequence_Tuple(ctl);  // a copy: the nodes stay what was given
    Py_XSETREF(s->keep, held != nullptr ? Py_BuildValue("(ONOOOO)", fdm, held, agl, phi, cas, nz)
                                        : nullptr);
    return s->keep != nullptr ? 0 : -1;
}

void stepper_dealloc(PyObject *self_)
{
    dealloc_keeping(self_, reinterpret_cast<Stepper *>(self_)->keep);
}

// run(t, n, pos, target, until, touchdown) -> DONE | TARGET | JUDGE
//
// Runs the physics steps that end at or before t, from step n on; `pos` (a list of 4 floats,
// the actuators' positions) is read first and written back last. Before a step that starts
// at or after `until` it returns TARGET (the target given no longer holds then); after a step
// it returns JUDGE when the Python must look at that step: out of the limits, or near the
// ground (`touchdown`: the wheels have touched, the load factor no longer counts there).
// `n` holds the steps done when it returns.
PyObject *stepper_run(PyObject *self_, PyObject *const *args, Py_ssize_t nargs)
{
    Stepper *s = reinterpret_cast<Stepper *>(self_);
    if (nargs != 6) {
        PyErr_SetString(PyExc_TypeError, "run(t, n, pos, target, until, touchdown)");
        return nullptr;
    }
    long long t = PyLong_AsLongLong(args[0]);
    long long n = PyLong_AsLongLong(args[1]);
    long long until = PyLong_AsLongLong(args[4]);
    int touchdown = PyObject_IsTrue(args[5]);
    if (PyErr_Occurred() || touchdown < 0)
        return nullptr;
    if (s->keep == nullptr) {
        PyErr_SetString(PyExc_RuntimeError, "the Stepper was not set up");
        return nullptr;
    }
    PyObject *pos_list = args[2];
    if (!PyList_CheckExact(pos_list) || PyList_GET_SIZE(pos_list) != 4) {
        PyErr_SetString(PyExc_TypeError, "pos: a list of 4 floats expected");
        return nullptr;
    }
    double pos[4], tgt[4];
    if (!seq_doubles(pos_list, pos, 4, "pos") || !seq_doubles(args[3], tgt, 4, "target"))
        return nullptr;
    const Jsb &j = s->jsb;
    int code = DONE;
    try {
        while ((n + 1) * NS / s->hz <= t) {
            if (n * NS / s->hz >= until) {
                code = TARGET;
                break;
            }
            // Actuators.step: each moves toward its target, within its limits, at its rate
            for (int i = 0; i < 4; i++) {
                double g = tgt[i];
                if (g < s->lo[i])
                    g = s->lo[i];
                else if (g > s->hi[i])
                    g = s->hi[i];
                double m = s->move[i];
                double d = g - pos[i];
                if (d > m)
                    d = m;
                else if (d < -m)
                    d = -m;
                pos[i] += d;
            }
            j.set(s->ctl[0], pos[0]);
            j.set(s->ctl[1], pos[1]);
            j.set(s->ctl[2], -pos[2]);
            j.set(s->ctl[3], pos[3]);
            j.run(s->fdm);
            n++;
            double a = j.get(s->agl), r = j.get(s->phi);
            if (!(a > 0.0) || !(-s->max_roll <= r && r <= s->max_roll)) {
                code = JUDGE;
                break;
            }
            double c = j.get(s->cas), z = j.get(s->nz);
            if (!(c <= s->max_cas) ||
                !(std::fabs(z) <= s->max_load || (touchdown && a < s->near_ground_ft))) {
                code = JUDGE;
                break;
            }
            if (a < s->near_ground_ft) {
                code = JUDGE;
                break;
            }
        }
    } catch (const std::exception &e) {
        s->n = n;
        PyErr_Format(PyExc_RuntimeError, "JSBSim failed at step %lld: %s", n, e.what());
        return nullptr;
    } catch (...) {
        s->n = n;
        PyErr_Format(PyExc_RuntimeError, "JSBSim failed at step %lld", n);
        return nullptr;
    }
    s->n = n;
    for (Py_ssize_t i = 0; i < 4; i++) {
        PyObject *v = PyFloat_FromDouble(pos[i]);
        if (v == nullptr)
            return nullptr;
        if (PyList_SetItem(pos_list, i, v) < 0)  // steals v, releases the old item
            return nullptr;
    }
    return PyLong_FromLong(code);
}

PyObject *stepper_get(PyObject *self_, PyObject *node)
{
    // get(node): a property node's value read as run() reads it (for the checks)
    Stepper *s = reinterpret_cast<Stepper *>(self_);
    if (s->keep == nullptr) {
        PyErr_SetString(PyExc_RuntimeError, "the Stepper was not set up");
        return nullptr;
    }
    void *p = jsb_node(s->jsb, node);
    if (p == nullptr)
        return nullptr;
    return PyFloat_FromDouble(s->jsb.get(p));
}

PyObject *stepper_n(PyObject *self_, void *)
{
    return PyLong_FromLongLong(reinterpret_cast<Stepper *>(self_)->n);
}

PyMethodDef stepper_methods[] = {
    {"run", fastcall(stepper_run),
     METH_FASTCALL, "run(t, n, pos, target, until, touchdown) -> DONE | TARGET | JUDGE"},
    {"get", stepper_get, METH_O, "get(node) -> the node's value, as run() reads it"},
    {nullptr, nullptr, 0, nullptr},
};

PyGetSetDef stepper_getset[] = {
    {"n", stepper_n, nullptr, "physics steps done", nullptr},
    {nullptr, nullptr, nullptr, nullptr, nullptr},
};

PyType_Slot stepper_slots[] = {
    {Py_tp_doc, const_cast<char *>("One aircraft's physics steps (see sim/core/stepper.cc).")},
    {Py_tp_new, reinterpret_cast<void *>(PyType_GenericNew)},
    {Py_tp_init, reinterpret_cast<void *>(stepper_init)},
    {Py_tp_dealloc, reinterpret_cast<void *>(stepper_dealloc)},
    {Py_tp_methods, stepper_methods},
    {Py_tp_getset, stepper_getset},
    {0, nullptr},
};

}  // namespace

PyType_Spec stepper_spec = {"imaworld._core.Stepper", sizeof(Stepper), 0, Py_TPFLAGS_DEFAULT,
                            stepper_slots};

}  // namespace core
