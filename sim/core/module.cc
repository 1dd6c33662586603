// SPDX-License-Identifier: Apache-2.0
// The Python module imaworld._core: the world's C++ (see sim/README.md, Speed), loaded by
// sim/imaworld/core.py from the build tree.

#include "core.h"
#include "core_digest.h"

void core::dealloc_keeping(PyObject *self, PyObject *keep)
{
    PyTypeObject *type = Py_TYPE(self);
    Py_XDECREF(keep);
    type->tp_free(self);
    Py_DECREF(type);  // a heap type: each instance holds a reference
}

namespace {


// json_number(x, ndigits) -> what json.dumps writes of world._r(x, ndigits), as the truth
// record writes it (for the tests)
PyObject *json_number(PyObject *, PyObject *args)
{
    double x;
    int nd;
    if (!PyArg_ParseTuple(args, "di", &x, &nd))
        return nullptr;
    char buf[40];
    return PyUnicode_FromStringAndSize(buf,
                                       static_cast<Py_ssize_t>(core::json_rounded(x, nd, buf)));
}

PyMethodDef module_methods[] = {
    {"json_number", json_number, METH_VARARGS,
     "json_number(x, ndigits) -> json.dumps of x rounded as the world rounds it"},
    {nullptr, nullptr, 0, nullptr},
};

PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT, "_core", "The world's C++: its physics steps, sensors and truth.", -1,
    module_methods, nullptr, nullptr, nullptr, nullptr,
};

bool add_type(PyObject *m, PyType_Spec *spec)
{
    PyObject *type = PyType_FromSpec(spec);
    bool ok = type != nullptr && PyModule_AddType(m, reinterpret_cast<PyTypeObject *>(type)) == 0;
    Py_XDECREF(type);  // the module holds its own reference
    return ok;
}

}  // namespace

PyMODINIT_FUNC PyInit__core(void);

PyMODINIT_FUNC PyInit__core(void)
{
    PyObject *m = PyModule_Create(&module_def);
    if (m == nullptr)
        return nullptr;
    if (!add_type(m, &core::stepper_spec) || !add_type(m, &core::normals_spec) ||
        !add_type(m, &core::ahrs_spec) || !add_type(m, &core::truth_spec) ||
        !add_type(m, &core::adc_spec) || PyModule_AddIntConstant(m, "DONE", core::DONE) < 0 ||
        PyModule_AddIntConstant(m, "TARGET", core::TARGET) < 0 ||
        PyModule_AddIntConstant(m, "JUDGE", core::JUDGE) < 0 ||
        PyModule_AddStringConstant(m, "SOURCE", CORE_SOURCE_DIGEST) < 0) {
        Py_DECREF(m);
        return nullptr;
    }
    return m;
}
