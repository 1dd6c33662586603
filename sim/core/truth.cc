// SPDX-License-Identifier: Apache-2.0
// The truth record in C++ (the Python's World.truth written by json.dumps, used through
// World._truth): the aircraft's state read from JSBSim, rounded and written as the Python
// rounds and writes it, the actuators' positions and the station's strings given by the
// Python. A string the JSON would have to escape is left to the Python (line() gives None).

#include "core.h"

#include <cmath>
#include <cstring>

namespace core {
namespace {

constexpr double KT_FPS = 1.6878098571011957;  // ft/s per knot, as world.py divides
constexpr double RAD_TO_DEG = 180.0 / M_PI;    // math.degrees
enum { LAT, LON, ALT, AGL, CAS, TAS, VN, VE, PSI, PHI, THETA, HDOT, WIND_N, WIND_E, NN };

struct Truth {
    PyObject_HEAD
    Jsb jsb;
    void *node[NN];
    PyObject *hypot, *atan2;  // Python's math.hypot and math.atan2
    PyObject *keep;
};

// The longest string written here (the modes and states are short words); with it the
// longest line (19 keys, 18 numbers of up to 24 characters, 4 strings) fits in Line::buf.
constexpr Py_ssize_t MAX_STR = 32;

struct Line {
    char buf[1024];
    size_t n = 0;
    void raw(const char *s) { put(s, strlen(s)); }
    void put(const char *s, size_t k)
    {
        memcpy(buf + n, s, k);
        n += k;
    }
    // ,"key": the value as world._r rounds it and json.dumps writes it
    void num(const char *key, double x, int nd)
    {
        raw(key);
        n += json_rounded(x, nd, buf + n);
    }
    bool str(const char *key, PyObject *s)
    {
        raw(key);
        if (s == Py_None) {
            raw("null");
            return true;
        }
        Py_ssize_t k;
        const char *u = PyUnicode_Check(s) ? PyUnicode_AsUTF8AndSize(s, &k) : nullptr;
        if (u == nullptr || k > MAX_STR) {
            PyErr_Clear();
            return false;
        }
        for (Py_ssize_t i = 0; i < k; i++)
            if (u[i] < 0x20 || u[i] > 0x7e || u[i] == '"' || u[i] == '\\')
                return false;
        buf[n++] = '"';
        put(u, static_cast<size_t>(k));
        buf[n++] = '"';
        return true;
    }
};

// f(a, b) of Python's math, as a double (NaN when it raises: _r writes null then, and the
// Python's truth() would have raised: the caller falls back to it)
bool call2(PyObject *f, double a, double b, double *out)
{
    PyObject *args[2] = {PyFloat_FromDouble(a), PyFloat_FromDouble(b)};
    PyObject *r = args[0] && args[1] ? PyObject_Vectorcall(f, args, 2, nullptr) : nullptr;
    Py_XDECREF(args[0]);
    Py_XDECREF(args[1]);
    if (r == nullptr) {
        PyErr_Clear();
        return false;
    }
    *out = PyFloat_AsDouble(r);
    Py_DECREF(r);
    return !PyErr_Occurred();
}

// line(t_ns, pos, fcs_mode, fcs_fallback, c2_link, gps) -> the JSON line with its newline,
// or None: the Python writes this one
PyObject *truth_line(PyObject *self_, PyObject *const *args, Py_ssize_t nargs)
{
    Truth *s = reinterpret_cast<Truth *>(self_);
    if (s->keep == nullptr) {
        PyErr_SetString(PyExc_RuntimeError, "the Truth was not set up");
        return nullptr;
    }
    if (nargs != 6) {
        PyErr_SetString(PyExc_TypeError, "line(t_ns, pos, mode, fallback, c2_link, gps)");
        return nullptr;
    }
    long long t = PyLong_AsLongLong(args[0]);
    double pos[4];
    if ((t == -1 && PyErr_Occurred()) || !seq_doubles(args[1], pos, 4, "pos"))
        return nullptr;
    double v[NN];
    for (int k = 0; k < NN; k++)
        v[k] = s->jsb.get(s->node[k]);
    double gs, trk;
    if (!call2(s->hypot, v[VN], v[VE], &gs) || !call2(s->atan2, v[VE], v[VN], &trk))
        Py_RETURN_NONE;
    Line L;
    L.raw("{\"t_ns\":");
    L.n += static_cast<size_t>(snprintf(L.buf + L.n, 24, "%lld", t));
    L.num(",\"lat_deg\":", v[LAT], 7);
    L.num(",\"lon_deg\":", v[LON], 7);
    L.num(",\"alt_ft\":", v[ALT], 2);
    L.num(",\"agl_ft\":", v[AGL], 2);
    L.num(",\"airspeed_kt\":", v[CAS], 3);
    L.num(",\"tas_kt\":", v[TAS], 3);
    L.num(",\"gs_kt\":", gs / KT_FPS, 3);
    L.num(",\"heading_deg\":", py_mod(v[PSI], 360.0), 3);
    L.num(",\"track_deg\":", py_mod(trk * RAD_TO_DEG, 360.0), 3);
    L.num(",\"roll_deg\":", v[PHI], 3);
    L.num(",\"pitch_deg\":", v[THETA], 3);
    L.num(",\"vs_fpm\":", v[HDOT] * 60.0, 1);
    L.num(",\"elev\":", pos[0], 4);
    L.num(",\"ail\":", pos[1], 4);
    L.num(",\"rud\":", pos[2], 4);
    L.num(",\"thr\":", pos[3], 4);
    if (!L.str(",\"fcs_mode\":", args[2]) || !L.str(",\"fcs_fallback\":", args[3]) ||
        !L.str(",\"c2_link\":", args[4]) || !L.str(",\"gps\":", args[5]))
        Py_RETURN_NONE;
    L.num(",\"wind_n_kt\":", v[WIND_N] / KT_FPS, 3);
    L.num(",\"wind_e_kt\":", v[WIND_E] / KT_FPS, 3);
    L.raw("}\n");
    return PyUnicode_FromStringAndSize(L.buf, static_cast<Py_ssize_t>(L.n));
}

// Truth(lib_path, nodes(14: lat, lon, alt, agl, cas, tas, vn, ve, psi, phi, theta, hdot,
//       wind_n, wind_e), hypot, atan2)
int truth_init(PyObject *self_, PyObject *args, PyObject *kw)
{
    Truth *s = reinterpret_cast<Truth *>(self_);
    const char *lib;
    PyObject *nodes, *hypot, *atan2;
    Py_CLEAR(s->keep);
    if ((kw != nullptr && PyDict_GET_SIZE(kw) != 0) ||
        !PyArg_ParseTuple(args, "sOOO", &lib, &nodes, &hypot, &atan2))
        return -1;
    if (!PyCallable_Check(hypot) || !PyCallable_Check(atan2)) {
        PyErr_SetString(PyExc_TypeError, "hypot and atan2: math's functions expected");
        return -1;
    }
    if (!jsb_resolve(lib, &s->jsb))
        return -1;
    if (!jsb_nodes(s->jsb, nodes, s->node, NN))
        return -1;
    s->hypot = hypot;
    s->atan2 = atan2;
    PyObject *held = PySequence_Tuple(nodes);  // a copy: the nodes stay what was given
    s->keep = held != nullptr ? Py_BuildValue("(NOO)", held, hypot, atan2) : nullptr;
    return s->keep != nullptr ? 0 : -1;
}

void truth_dealloc(PyObject *self_)
{
    dealloc_keeping(self_, reinterpret_cast<Truth *>(self_)->keep);
}

PyMethodDef truth_methods[] = {
    {"line", fastcall(truth_line),
     METH_FASTCALL, "line(t_ns, pos, fcs_mode, fcs_fallback, c2_link, gps) -> str or None"},
    {nullptr, nullptr, 0, nullptr},
};

PyType_Slot truth_slots[] = {
    {Py_tp_doc, const_cast<char *>("The truth record (see sim/core/truth.cc).")},
    {Py_tp_new, reinterpret_cast<void *>(PyType_GenericNew)},
    {Py_tp_init, reinterpret_cast<void *>(truth_init)},
    {Py_tp_dealloc, reinterpret_cast<void *>(truth_dealloc)},
    {Py_tp_methods, truth_methods},
    {0, nullptr},
};

}  // namespace

PyType_Spec truth_spec = {"imaworld._core.Truth", sizeof(Truth), 0, Py_TPFLAGS_DEFAULT,
                          truth_slots};

}  // namespace core
