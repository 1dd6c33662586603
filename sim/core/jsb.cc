// SPDX-License-Identifier: Apache-2.0
// JSBSim from C++: the functions the jsbsim wheel's library exports, and the C++ objects its
// Python objects wrap (see core.h).

#include "core.h"

#include <dlfcn.h>

#include <cstring>

namespace core {

namespace {

// The C++ object a jsbsim Python object of class `cls` wraps: the first of its fields (the
// words after the object header, within the class's size) that points at an object whose
// vtable is `vt`. Only objects of that class of the jsbsim library itself (its type's
// functions are the library's) are looked into: their fields are pointers or null.
void *wrapped(const Jsb &j, PyObject *o, const char *cls, const void *vt)
{
    PyTypeObject *type = Py_TYPE(o);
    const char *name = type->tp_name;
    const char *dot = strrchr(name, '.');
    Dl_info info;
    if (strcmp(dot != nullptr ? dot + 1 : name, cls) == 0 &&
        dladdr(reinterpret_cast<void *>(type->tp_dealloc), &info) != 0 &&
        info.dli_fbase == j.base) {
        void **words = reinterpret_cast<void **>(o);
        size_t size = static_cast<size_t>(type->tp_basicsize) / sizeof(void *);
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

}  // namespace

void *jsb_fdm(const Jsb &j, PyObject *o)
{
    return wrapped(j, o, "FGFDMExec", j.vt_fdm);
}

void *jsb_node(const Jsb &j, PyObject *o)
{
    return wrapped(j, o, "FGPropertyNode", j.vt_node);
}

bool jsb_nodes(const Jsb &j, PyObject *seq, void **out, Py_ssize_t n)
{
    PyObject *fast = PySequence_Fast(seq, "nodes");
    if (fast == nullptr)
        return false;
    bool ok = PySequence_Fast_GET_SIZE(fast) == n;
    for (Py_ssize_t k = 0; ok && k < n; k++)
        ok = (out[k] = jsb_node(j, PySequence_Fast_GET_ITEM(fast, k))) != nullptr;
    Py_DECREF(fast);
    if (!ok && !PyErr_Occurred())
        PyErr_Format(PyExc_ValueError, "nodes: %zd property nodes expected", n);
    return ok;
}

bool jsb_resolve(const char *lib_path, Jsb *j)
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
    Dl_info info;
    if (dladdr(run, &info) == 0) {
        PyErr_Format(PyExc_ImportError, "cannot tell where %s is loaded", lib_path);
        return false;
    }
    j->base = info.dli_fbase;
    j->run = reinterpret_cast<run_fn>(run);
    j->get = reinterpret_cast<get_fn>(get);
    j->set = reinterpret_cast<set_fn>(set);
    // A vtable pointer points past the offset-to-top and typeinfo words.
    j->vt_fdm = static_cast<char *>(vt_fdm) + 2 * sizeof(void *);
    j->vt_node = static_cast<char *>(vt_node) + 2 * sizeof(void *);
    return true;
}

bool seq_doubles(PyObject *seq, double *out, Py_ssize_t n, const char *what)
{
    PyObject *fast = PySequence_Fast(seq, what);
    if (fast == nullptr)
        return false;
    if (PySequence_Fast_GET_SIZE(fast) != n) {
        Py_DECREF(fast);
        PyErr_Format(PyExc_ValueError, "%s: %zd values expected", what, n);
        return false;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        out[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(fast, i));
        if (out[i] == -1.0 && PyErr_Occurred()) {
            Py_DECREF(fast);
            return false;
        }
    }
    Py_DECREF(fast);
    return true;
}

}  // namespace core
