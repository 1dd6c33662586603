// SPDX-License-Identifier: Apache-2.0
// What the world's C++ (the Python module imaworld._core, sim/core/*.cc) shares: JSBSim's
// exported functions and the objects the jsbsim wheel wraps, a sequence read as doubles, and
// the module's types.
#pragma once

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <cstdint>

namespace core {

constexpr int64_t NS = 1000000000;

// What Stepper.run returns.
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
    const void *base;     // where the library is loaded
};

// The functions of the jsbsim wheel's library `lib_path` (already loaded by the jsbsim module).
bool jsb_resolve(const char *lib_path, Jsb *j);

// The JSBSim object a jsbsim FGFDMExec or FGPropertyNode Python object wraps, its class and
// vtable checked; nullptr with a TypeError set if it is not one.
void *jsb_fdm(const Jsb &j, PyObject *o);
void *jsb_node(const Jsb &j, PyObject *o);
// The JSBSim property nodes of a sequence of exactly n of them; false with an exception set.
bool jsb_nodes(const Jsb &j, PyObject *seq, void **out, Py_ssize_t n);

// n doubles from a sequence of exactly n numbers; false with an exception set otherwise.
bool seq_doubles(PyObject *seq, double *out, Py_ssize_t n, const char *what);

// A stream of standard normal draws (normals.cc): blocks from a Python callable.
struct Normals {
    PyObject_HEAD
    PyObject *draw;  // draw() -> the next block, a sequence of floats
    double *block;
    Py_ssize_t i, n;
};

// Whether o is a Normals.
bool is_normals(PyObject *o);

// The next draw; false with an exception set if a new block cannot be had.
bool normals_next(Normals *s, double *x);

// A sensor's first-order Gauss-Markov biases (sensors.GaussMarkov): x = a x + q n().
constexpr int MAX_BIASES = 9;
struct Biases {
    double a[MAX_BIASES], q[MAX_BIASES], x[MAX_BIASES];
};
// Exactly n of them from ((a, q, x), ...); false with an exception set.
bool biases_parse(PyObject *seq, Biases *b, int n);
// Bias k's next value, drawn from n.
bool biases_step(Biases *b, int k, Normals *n, double *out);

// What a type of the module does when an object of it goes: `keep` released, the object
// freed, its heap type released.
void dealloc_keeping(PyObject *self, PyObject *keep);

// A METH_FASTCALL function as PyMethodDef holds it (the cast CPython's API asks for).
inline PyCFunction fastcall(PyObject *(*f)(PyObject *, PyObject *const *, Py_ssize_t))
{
    return reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)(void)>(f));
}

// One CAN message as ima.canbus.codec encodes it (codec.cc).
constexpr int MSG_MAX_SIGNALS = 16;
struct Sig {
    int start, length;
    bool is_signed;
    double scale, offset;
};
struct Msg {
    uint32_t id;
    int length;
    int nsig;
    Sig sig[MSG_MAX_SIGNALS];
};

// spec: (frame_id, length, ((start, length, signed, scale, offset), ...)).
bool msg_parse(PyObject *spec, Msg *m);
// The message's bytes for the signals' values v (DBC order); false if a value is not finite
// (the Python's round() raises then).
bool msg_encode(const Msg *m, const double *v, uint8_t out[8]);
// (frame_id, bytes); nullptr with no exception set if a value is not finite.
PyObject *msg_frame(const Msg *m, const double *v);

// Floats as the Python computes and writes them (pyfloat.cc): x % y; round(x, ndigits);
// repr(x) of a finite x into out (at most 32 chars), its length returned.
double py_mod(double x, double y);
double py_round(double x, int ndigits);
size_t py_repr(double x, char *out);
// What json.dumps writes of world._r(x, ndigits) (null when not finite), into out (at most
// 32 chars), its length returned.
size_t json_rounded(double x, int ndigits, char *out);

extern PyType_Spec stepper_spec;
extern PyType_Spec normals_spec;
extern PyType_Spec ahrs_spec;
extern PyType_Spec truth_spec;
extern PyType_Spec adc_spec;

}  // namespace core
