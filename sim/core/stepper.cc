// SPDX-License-Identifier: Apache-2.0
// The world's physics steps in C++ (Python module imaworld._stepper, loaded by
// sim/imaworld/stepper.py): the smart actuators' rate limits, the controls handed to JSBSim,
// JSBSim's step, and the watch on the crash limits, for every step up to an instant, in one
// call. It drives the JSBSim of the `jsbsim` wheel, the very object the Python holds, through
// the C++ functions that wheel's _jsbsim.so exports, so a step computes what the Python's
// World.advance computes, to the bit.
//
// It leaves to the Python what happens rarely: it returns when the actuators need a target
// (the Python's Actuators._target, at an instant the Python names), and after any step whose
// state is near a crash limit or near the ground (the Python then judges that step itself).

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <dlfcn.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>

namespace {

constexpr int64_t NS = 1000000000;
constexpr const char *NODE = "FGPropertyNode";

// What run() returns.
enum : int { DONE = 0, TARGET = 1, JUDGE = 2 };

// The exported C++ functions, as plain functions taking `this` first (Itanium C++ ABI).
using run_fn = bool (*)(void *fdm);
using get_fn = double (*)(const void *node);
using set_fn = bool (*)(void *node, double value);

struct Jsb {
    run_fn run;
    get_fn get;
    set_fn set;
    const void *vt_fdm;   // where an FGFDMExec's vtable pointer points
    const void *vt_node;  // where an SGPropertyNode's vtable pointer points
};

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

// The C++ object a jsbsim Python object of class `cls` wraps: the first of its fields
// (the words after the object header, within the class's size) that points at an object
// whose vtable is `vt`. Only objects of that class are looked into: their fields are
// pointers or null, never a value that cannot be dereferenced.
void *wrapped(PyObject *o, const char *cls, const void *vt)
{
    const char *name = Py_TYPE(o)->tp_name;
    const char *dot = strrchr(name, '.');
    if (strcmp(dot != nullptr ? dot + 1 : name, cls) == 0) {
        void **words = reinterpret_cast<void **>(o);
        size_t size = static_cast<size_t>(Py_TYPE(o)->tp_basicsize) / sizeof(void *);
        for (size_t i = 2; i < size; i++) {
            void *p = words[i];
            if (p != nullptr && (reinterpret_cast<uintptr_t>(p) & 7) == 0 &&
                *static_cast<void *const *>(p) == vt)
                return p;
        }
    }
    PyErr_Format(PyExc_TypeError, "%s is not a jsbsim %s wrapping a JSBSim object", name, cls);
    return nullptr;
}

bool resolve(const char *lib_path, Jsb *j)
{
    void *h = dlopen(lib_path, RTLD_NOW | RTLD_NOLOAD);
    if (h == nullptr) {
        PyErr_Format(PyExc_ImportError, "JSBSim's library %s is not loaded", lib_path);
        return false;
    }
    void *run = dlsym(h, "_ZN6JSBSim9FGFDMExec3RunEv");
    void *get = dlsym(h, "_ZNK14SGPropertyNode14getDoubleValueEv");
    void *set = dlsym(h, "_ZN14SGPropertyNode14setDoubleValueEd");
    void *vt_fdm = dlsym(h, "_ZTVN6JSBSim9FGFDMExecE");
    void *vt_node = dlsym(h, "_ZTV14SGPropertyNode");
    dlclose(h);  // still loaded: the jsbsim module holds it
    if (!run || !get || !set || !vt_fdm || !vt_node) {
        PyErr_Format(PyExc_ImportError, "%s does not export the JSBSim functions needed",
                     lib_path);
        return false;
    }
    j->run = reinterpret_cast<run_fn>(run);
    j->get = reinterpret_cast<get_fn>(get);
    j->set = reinterpret_cast<set_fn>(set);
    // A vtable pointer points past the offset-to-top and typeinfo words.
    j->vt_fdm = static_cast<char *>(vt_fdm) + 2 * sizeof(void *);
    j->vt_node = static_cast<char *>(vt_node) + 2 * sizeof(void *);
    return true;
}

bool doubles(PyObject *seq, double out[4], const char *what)
{
    PyObject *fast = PySequence_Fast(seq, what);
    if (fast == nullptr)
        return false;
    if (PySequence_Fast_GET_SIZE(fast) != 4) {
        Py_DECREF(fast);
        PyErr_Format(PyExc_ValueError, "%s: 4 values expected", what);
        return false;
    }
    for (int i = 0; i < 4; i++) {
        out[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(fast, i));
        if (out[i] == -1.0 && PyErr_Occurred()) {
            Py_DECREF(fast);
            return false;
        }
    }
    Py_DECREF(fast);
    return true;
}

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
    if (!resolve(lib, &s->jsb))
        return -1;
    s->fdm = wrapped(fdm, "FGFDMExec", s->jsb.vt_fdm);
    if (s->fdm == nullptr)
        return -1;
    PyObject *fast = PySequence_Fast(ctl, "controls");
    if (fast == nullptr)
        return -1;
    if (PySequence_Fast_GET_SIZE(fast) != 4) {
        Py_DECREF(fast);
        PyErr_SetString(PyExc_ValueError, "controls: 4 property nodes expected");
        return -1;
    }
    for (int i = 0; i < 4; i++) {
        s->ctl[i] = wrapped(PySequence_Fast_GET_ITEM(fast, i), NODE, s->jsb.vt_node);
        if (s->ctl[i] == nullptr) {
            Py_DECREF(fast);
            return -1;
        }
    }
    Py_DECREF(fast);
    const void *vt = s->jsb.vt_node;
    if (!(s->agl = wrapped(agl, NODE, vt)) || !(s->phi = wrapped(phi, NODE, vt)) ||
        !(s->cas = wrapped(cas, NODE, vt)) || !(s->nz = wrapped(nz, NODE, vt)))
        return -1;
    if (!doubles(lo, s->lo, "lo") || !doubles(hi, s->hi, "hi") ||
        !doubles(moves, s->move, "moves"))
        return -1;
    s->hz = hz;
    s->n = 0;
    Py_XSETREF(s->keep, Py_BuildValue("(OOOOOO)", fdm, ctl, agl, phi, cas, nz));
    return s->keep != nullptr ? 0 : -1;
}

void stepper_dealloc(PyObject *self_)
{
    PyTypeObject *type = Py_TYPE(self_);
    Py_XDECREF(reinterpret_cast<Stepper *>(self_)->keep);
    type->tp_free(self_);
    Py_DECREF(type);  // a heap type: each instance holds a reference
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
    if (!doubles(pos_list, pos, "pos") || !doubles(args[3], tgt, "target"))
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
    void *p = wrapped(node, NODE, s->jsb.vt_node);
    if (p == nullptr)
        return nullptr;
    return PyFloat_FromDouble(s->jsb.get(p));
}

PyObject *stepper_n(PyObject *self_, void *)
{
    return PyLong_FromLongLong(reinterpret_cast<Stepper *>(self_)->n);
}

PyMethodDef stepper_methods[] = {
    {"run", reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)(void)>(stepper_run)),
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

PyType_Spec stepper_spec = {"imaworld._stepper.Stepper", sizeof(Stepper), 0, Py_TPFLAGS_DEFAULT,
                            stepper_slots};

PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT, "_stepper", "The world's physics steps in C++.", -1,
    nullptr, nullptr, nullptr, nullptr, nullptr,
};

}  // namespace

PyMODINIT_FUNC PyInit__stepper(void);

PyMODINIT_FUNC PyInit__stepper(void)
{
    PyObject *m = PyModule_Create(&module_def);
    if (m == nullptr)
        return nullptr;
    PyObject *type = PyType_FromSpec(&stepper_spec);
    bool bad = type == nullptr ||
               PyModule_AddType(m, reinterpret_cast<PyTypeObject *>(type)) < 0 ||
               PyModule_AddIntConstant(m, "DONE", DONE) < 0 ||
               PyModule_AddIntConstant(m, "TARGET", TARGET) < 0 ||
               PyModule_AddIntConstant(m, "JUDGE", JUDGE) < 0;
    Py_XDECREF(type);  // the module holds its own reference
    if (bad) {
        Py_DECREF(m);
        return nullptr;
    }
    return m;
}
