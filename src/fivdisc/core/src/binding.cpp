// The Python face of the core (nanobind): the model's arrays checked and wrapped into
// the named structs, the integrator object that keeps its state between calls, and the
// right-hand-side evaluations the analyses use. No input that passes the checks here can
// make the core read or write out of bounds; a failed check, or any C++ exception,
// becomes fivdisc.errors.CoreError with a one-line message.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "floor.hpp"
#include "integrator.hpp"

namespace nb = nanobind;
using namespace nb::literals;
using namespace fivdisc;

namespace {

struct CoreError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

PyObject* core_error_type = nullptr;

[[noreturn]] void fail(const std::string& what) { throw CoreError(what); }

using Array = nb::ndarray<const double, nb::c_contig, nb::device::cpu>;
using IntArray = nb::ndarray<const int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Out = nb::ndarray<nb::numpy, double>;

std::string shape_of(const Array& a) {
    std::string s = "(";
    for (size_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

void need_shape(const Array& a, const char* name, std::initializer_list<long> shape) {
    bool ok = a.ndim() == shape.size();
    size_t d = 0;
    for (long s : shape) {
        if (ok && s >= 0 && static_cast<long>(a.shape(d)) != s) ok = false;
        ++d;
    }
    if (!ok) {
        std::string want = "(";
        d = 0;
        for (long s : shape) want += (d++ ? ", " : "") + (s >= 0 ? std::to_string(s) : std::string("any"));
        fail(std::string(name) + " has shape " + shape_of(a) + ": must be " + want + (shape.size() == 1 ? ",)" : ")"));
    }
}

void need_finite(const Array& a, const char* name) {
    const double* p = a.data();
    for (size_t i = 0; i < a.size(); ++i)
        if (!std::isfinite(p[i])) fail(std::string(name) + " has a value that is not finite");
}

// New numpy arrays that own their data.
Out new_array(std::initializer_list<size_t> shape, double** data) {
    size_t count = 1;
    for (size_t s : shape) count *= s;
    double* p = new double[count > 0 ? count : 1]();
    nb::capsule owner(p, [](void* q) noexcept { delete[] static_cast<double*>(q); });
    *data = p;
    return Out(p, shape.size(), shape.begin(), owner);
}

nb::ndarray<nb::numpy, int64_t> new_int_array(std::initializer_list<size_t> shape, int64_t** data) {
    size_t count = 1;
    for (size_t s : shape) count *= s;
    int64_t* p = new int64_t[count > 0 ? count : 1]();
    nb::capsule owner(p, [](void* q) noexcept { delete[] static_cast<int64_t*>(q); });
    *data = p;
    return nb::ndarray<nb::numpy, int64_t>(p, shape.size(), shape.begin(), owner);
}

// Rows of the model arrays fivdisc.model.build_model makes (fivdisc.core.layout).
enum { D_SGN, D_L, D_PARTNER, D_MINV, D_KD, D_ML2, D_GYR, D_OMD_FIX, D_CDAMP, D_CDAMP_OM, N_DISC };
enum { S_THETA, S_SIGMA, S_MASS, S_INERTIA, S_KZ, S_CZ, S_KPHI, S_CPHI, S_N0, S_RADIUS, S_HH,
       S_SMASS, S_SKZ, S_SCZ, S_SN0, S_SHH, N_SLIDER };
enum { O_LAW, O_MUS, O_MU0, O_MU1, O_ALPHA, O_VS, O_DELTA, O_MUV, O_OMDOT, O_IMPACT, O_LMAX,
       O_DAMPED, O_MIN_FLIGHT, N_OPTS };

// Largest nodal-diameter count, work array (values) and output (values) the core accepts.
constexpr int MAX_L = 100000;
constexpr double MAX_WORK = 2e7;
constexpr double MAX_OUTPUT = 1e9;

Pieces pieces(const Array& a, const char* name) {
    if (a.ndim() != 2 || a.shape(1) != 5 || a.shape(0) < 1)
        fail(std::string(name) + " has shape " + shape_of(a) + ": must be (k, 5) with k >= 1");
    need_finite(a, name);
    Pieces p;
    p.count = static_cast<int>(a.shape(0));
    p.rows.assign(a.data(), a.data() + a.size());
    for (int k = 1; k < p.count; ++k)
        if (!(p.start(k) > p.start(k - 1))) fail(std::string(name) + "'s piece starts must increase");
    p.flat = p.count == 1 && p.c(0, 1) == 0.0 && p.c(0, 2) == 0.0 && p.c(0, 3) == 0.0;
    return p;
}

std::vector<double> row(const Array& a, int r) {
    const size_t w = a.shape(1);
    return std::vector<double>(a.data() + r * w, a.data() + (r + 1) * w);
}

// The checked model.
Model make_model(const Array& disc, const Array& slider, const Array& shape, const Array& table,
                 const Array& speed, const Array& opts) {
    if (disc.ndim() != 2 || disc.shape(0) != N_DISC)
        fail("disc has shape " + shape_of(disc) + ": must be (" + std::to_string(N_DISC) + ", n)");
    if (slider.ndim() != 2 || slider.shape(0) != N_SLIDER || slider.shape(1) < 1)
        fail("slider has shape " + shape_of(slider) + ": must be (" + std::to_string(N_SLIDER) +
             ", S) with S >= 1");
    const long n = static_cast<long>(disc.shape(1));
    const long S = static_cast<long>(slider.shape(1));
    need_shape(opts, "opts", {N_OPTS});
    need_finite(opts, "opts");
    const double lw = std::fabs(opts.data()[O_LMAX]) + 2.0;
    if (!(static_cast<double>(S) * (3.0 * n + 2.0 * lw + S + 1.0) <= MAX_WORK))
        fail("the model is too large for the core: " + std::to_string(n) + " modal coordinates, " +
             std::to_string(S) + " sliders");
    need_shape(shape, "shape", {S, n});
    need_finite(disc, "disc");
    need_finite(slider, "slider");
    need_finite(shape, "shape");
    Model m;
    m.n = static_cast<int>(n);
    m.S = static_cast<int>(S);
    Disc& d = m.disc;
    d.sgn = row(disc, D_SGN);
    d.l = row(disc, D_L);
    d.minv = row(disc, D_MINV);
    d.kd = row(disc, D_KD);
    d.ml2 = row(disc, D_ML2);
    d.gyr = row(disc, D_GYR);
    d.omd_fix = row(disc, D_OMD_FIX);
    d.cdamp = row(disc, D_CDAMP);
    d.cdamp_om = row(disc, D_CDAMP_OM);
    const std::vector<double> partner = row(disc, D_PARTNER);
    const double* o = opts.data();
    const double lmax = o[O_LMAX];
    if (!(lmax >= 0 && lmax <= MAX_L && lmax == std::floor(lmax)))
        fail("opts: the largest l must be a whole number from 0 to " + std::to_string(MAX_L));
    m.lmax = static_cast<int>(lmax);
    d.li.resize(n);
    d.l2.resize(n);
    d.cs.resize(n);
    d.sn.resize(n);
    d.partner.resize(n);
    for (long i = 0; i < n; ++i) {
        const double l = d.l[i];
        if (!(l >= 0 && l <= lmax && l == std::floor(l)))
            fail("disc: l of coordinate " + std::to_string(i) + " must be a whole number from 0 to the largest l");
        if (!(d.sgn[i] == 1.0 || d.sgn[i] == -1.0))
            fail("disc: the cosine/sine flag of coordinate " + std::to_string(i) + " must be +1 or -1");
        d.li[i] = static_cast<int>(l);
        d.l2[i] = l * l;
        d.cs[i] = 0.5 + 0.5 * d.sgn[i];
        d.sn[i] = 0.5 - 0.5 * d.sgn[i];
        const double p = partner[i];
        if (!(p == -1 || (p >= 0 && p < n && p == std::floor(p) && p != i)))
            fail("disc: the partner of coordinate " + std::to_string(i) + " must be -1 or another coordinate");
        d.partner[i] = static_cast<int>(p);
    }
    Sliders& s = m.sl;
    s.theta = row(slider, S_THETA);
    s.sigma = row(slider, S_SIGMA);
    s.mass = row(slider, S_MASS);
    s.inertia = row(slider, S_INERTIA);
    s.kz = row(slider, S_KZ);
    s.cz = row(slider, S_CZ);
    s.kphi = row(slider, S_KPHI);
    s.cphi = row(slider, S_CPHI);
    s.n0 = row(slider, S_N0);
    s.radius = row(slider, S_RADIUS);
    s.hh = row(slider, S_HH);
    s.smass = row(slider, S_SMASS);
    s.skz = row(slider, S_SKZ);
    s.scz = row(slider, S_SCZ);
    s.sn0 = row(slider, S_SN0);
    s.shh = row(slider, S_SHH);
    m.shape.assign(shape.data(), shape.data() + shape.size());
    const double law = o[O_LAW];
    if (!(law == LAW_EXPONENTIAL || law == LAW_STRIBECK || law == LAW_TABLE))
        fail("opts: the friction law must be 0 (exponential), 1 (stribeck) or 2 (table)");
    Friction& fr = m.fr;
    fr.law = static_cast<int>(law);
    fr.mus = o[O_MUS];
    fr.mu0 = o[O_MU0];
    fr.mu1 = o[O_MU1];
    fr.alpha = o[O_ALPHA];
    fr.vs = o[O_VS];
    fr.delta = o[O_DELTA];
    fr.muv = o[O_MUV];
    fr.table = pieces(table, "table");
    m.speed = pieces(speed, "speed");
    m.omdot = o[O_OMDOT];
    m.impact = o[O_IMPACT] != 0.0;
    m.damped = o[O_DAMPED] != 0.0;
    m.min_flight = o[O_MIN_FLIGHT];
    return m;
}

// A model as a Python object, checked once and shared by the calls that take it.
struct PyModel {
    Model m;
};

Layout layout_of(const Model& m, const Array& y, const char* name, bool allow_energy = true) {
    const long nd = 2 * (m.n + 2 * m.S);
    if (y.ndim() != 1 || !(static_cast<long>(y.shape(0)) == nd ||
                           (allow_energy && static_cast<long>(y.shape(0)) == nd + N_ENERGY)))
        fail(std::string(name) + " has shape " + shape_of(y) + ": must be (" + std::to_string(nd) + ",)" +
             (allow_energy ? " or (" + std::to_string(nd + N_ENERGY) + ",) with the energy accumulators" : ""));
    return Layout(m, static_cast<long>(y.shape(0)) > nd);
}

std::vector<int> phases_of(const Model& m, const IntArray& ph) {
    if (static_cast<long>(ph.shape(0)) != m.S) fail("phases must have one value per slider (" + std::to_string(m.S) + ")");
    std::vector<int> p(m.S);
    for (int j = 0; j < m.S; ++j) {
        const int64_t a = ph.data()[j];
        if (a < SLIP || a > SEPARATION)
            fail("phase of slider " + std::to_string(j) + " must be 0 (slip), 1 (stick) or 2 (separation)");
        p[j] = static_cast<int>(a);
    }
    return p;
}

void phases_of(const Model& m, const IntArray& ph, const IntArray& sg, std::vector<int>& p, std::vector<int>& s) {
    p = phases_of(m, ph);
    if (static_cast<long>(sg.shape(0)) != m.S) fail("signs must have one value per slider (" + std::to_string(m.S) + ")");
    s.resize(m.S);
    for (int j = 0; j < m.S; ++j) {
        const int64_t b = sg.data()[j];
        if (b != 1 && b != -1) fail("slip sign of slider " + std::to_string(j) + " must be +1 or -1");
        s[j] = static_cast<int>(b);
    }
}

nb::dict aux_dict(const Model& m, const Work<double>& wk) {
    const SliderAux<double>& a = wk.aux;
    nb::dict out;
    auto put = [&](const char* name, const std::vector<double>& v) {
        double* p;
        Out arr = new_array({static_cast<size_t>(m.S)}, &p);
        for (int j = 0; j < m.S; ++j) p[j] = v[j];
        out[name] = arr;
    };
    put("normal_force", a.N);
    put("friction_force", a.F);
    put("w", a.wc);
    put("w_rate", a.wcd);
    put("relative_speed", a.v);
    put("gpq", a.gpq);
    put("phi_dot", a.phid);
    double* g;
    double* gp;
    Out ga = new_array({static_cast<size_t>(m.S), static_cast<size_t>(m.n)}, &g);
    Out gpa = new_array({static_cast<size_t>(m.S), static_cast<size_t>(m.n)}, &gp);
    for (size_t i = 0; i < wk.g.size(); ++i) {
        g[i] = wk.g[i];
        gp[i] = wk.gp[i];
    }
    out["g"] = ga;
    out["g_prime"] = gpa;
    return out;
}

// The integrator, with a guard against a second call while one runs (the GIL is released).
struct PyIntegrator {
    Integrator it;
    // The samples' numpy arrays, which the integrator writes into (made by numpy, so
    // that Python's memory accounting sees them).
    nb::object out_y, out_aux;
    std::atomic<bool> busy{false};
    struct Guard {
        std::atomic<bool>& b;
        explicit Guard(std::atomic<bool>& b_) : b(b_) {
            if (b.exchange(true)) fail("the integrator is busy in another thread");
        }
        ~Guard() { b.store(false); }
    };
};

}  // namespace

NB_MODULE(_core, m) {
    m.doc() = "fivdisc's compiled core: the non-smooth integrator and the right-hand side (C++).";
    // The command line freezes the garbage collector once its output is written (a full
    // collection over scipy's and xarray's objects costs a short command up to 0.4 s), so
    // a model or run left in a reference cycle is still alive when this module is torn
    // down; nanobind would report each as a leak on stderr after every such command. No
    // object of this module owns anything but memory, which the exit returns.
    nb::set_leak_warnings(false);

    // CoreError is fivdisc's own error (FivdiscError) and a ValueError.
    nb::object base = nb::module_::import_("fivdisc.errors").attr("FivdiscError");
    nb::dict ns;
    ns["__module__"] = "fivdisc.core";
    ns["__doc__"] = "Input the compiled core refuses, or a failure inside it (one-line message).";
    nb::object cls = nb::module_::import_("builtins").attr("type")(
        "CoreError", nb::make_tuple(base, nb::handle(PyExc_ValueError)), ns);
    m.attr("CoreError") = cls;
    core_error_type = cls.release().ptr();
    nb::register_exception_translator([](const std::exception_ptr& p, void*) {
        try {
            std::rethrow_exception(p);
        } catch (const CoreError& e) {
            PyErr_SetString(core_error_type, e.what());
        } catch (const std::bad_alloc&) {
            PyErr_SetString(core_error_type, "the compiled core ran out of memory");
        } catch (const nb::python_error&) {
            throw;
        } catch (const nb::builtin_exception&) {
            throw;
        } catch (const std::exception& e) {
            PyErr_SetString(core_error_type, (std::string("error in the compiled core: ") + e.what()).c_str());
        }
    });

    m.attr("SLIP") = static_cast<int>(SLIP);
    m.attr("STICK") = static_cast<int>(STICK);
    m.attr("SEPARATION") = static_cast<int>(SEPARATION);
    m.attr("N_ENERGY") = static_cast<int>(N_ENERGY);
    m.attr("EVENT_BUFFER") = 1 << 15;

    nb::class_<PyModel>(m, "Model",
        "The model's arrays, checked and held as named fields (fivdisc.core.layout gives the rows).")
        .def("__init__",
             [](PyModel* self, const Array& disc, const Array& slider, const Array& shape,
                const Array& table, const Array& speed, const Array& opts) {
                 new (self) PyModel{make_model(disc, slider, shape, table, speed, opts)};
             },
             "disc"_a, "slider"_a, "shape"_a, "table"_a, "speed"_a, "opts"_a)
        .def_prop_ro("n", [](const PyModel& s) { return s.m.n; })
        .def_prop_ro("n_sliders", [](const PyModel& s) { return s.m.S; });

    m.def("rhs",
          [](const PyModel& pm, double t, const Array& y, const IntArray& ph, const IntArray& sg, bool right) {
              const Model& M = pm.m;
              const Layout L = layout_of(M, y, "y");
              std::vector<int> p, s;
              phases_of(M, ph, sg, p, s);
              double* dy;
              Out out = new_array({static_cast<size_t>(L.size)}, &dy);
              Work<double> wk(M);
              evaluate<double, double>(M, t, y.data(), L.size, p.data(), s.data(), right, wk, dy);
              return out;
          },
          "model"_a, "t"_a, "y"_a, "phases"_a, "signs"_a, "right"_a = true,
          "Time derivative of the state y at t, slider j in phase phases[j] with slip sign signs[j]; right: "
          "the right limit of the speed at a knot.");

    m.def("evaluate",
          [](const PyModel& pm, double t, const Array& y, const IntArray& ph, const IntArray& sg, bool right) {
              const Model& M = pm.m;
              const Layout L = layout_of(M, y, "y");
              std::vector<int> p, s;
              phases_of(M, ph, sg, p, s);
              double* dy;
              Out out = new_array({static_cast<size_t>(L.size)}, &dy);
              Work<double> wk(M);
              evaluate<double, double>(M, t, y.data(), L.size, p.data(), s.data(), right, wk, dy);
              return nb::make_tuple(out, aux_dict(M, wk));
          },
          "model"_a, "t"_a, "y"_a, "phases"_a, "signs"_a, "right"_a = true,
          "(rhs, aux): the time derivative and a dict of per-slider arrays: normal_force [N], "
          "friction_force [N], w [m], w_rate [m/s], relative_speed [rad/s], gpq, phi_dot [rad/s], and "
          "(S, n) arrays g and g_prime: the mode shapes at each slider and their angular derivatives.");

    m.def("event_values",
          [](const PyModel& pm, double t, const Array& y, const IntArray& ph, const IntArray& sg, bool right) {
              const Model& M = pm.m;
              const Layout L = layout_of(M, y, "y");
              std::vector<int> p, s;
              phases_of(M, ph, sg, p, s);
              std::vector<double> dy(L.size);
              Work<double> wk(M);
              evaluate<double, double>(M, t, y.data(), L.size, p.data(), s.data(), right, wk, dy.data());
              double* ev;
              Out out = new_array({static_cast<size_t>(3 * M.S)}, &ev);
              event_values(M, p.data(), s.data(), y.data(), wk, ev);
              return out;
          },
          "model"_a, "t"_a, "y"_a, "phases"_a, "signs"_a, "right"_a = true,
          "The event functions of every slider's phase (3 per slider, positive while it holds, unused +inf).");

    m.def("jacobian",
          [](const PyModel& pm, double t, const Array& y, const IntArray& ph, const IntArray& sg) {
              const Model& M = pm.m;
              const Layout L = layout_of(M, y, "y");
              std::vector<int> p, s;
              phases_of(M, ph, sg, p, s);
              const int ny = L.size;
              double* jac;
              Out out = new_array({static_cast<size_t>(ny), static_cast<size_t>(ny)}, &jac);
              {
                  nb::gil_scoped_release release;
                  std::vector<Cx> yc(ny), dy(ny);
                  Work<Cx> wk(M);
                  const double step = 1e-30;
                  for (int i = 0; i < ny; ++i) {
                      for (int j = 0; j < ny; ++j) yc[j] = Cx(y.data()[j]);
                      yc[i] = Cx(y.data()[i], step);
                      evaluate<Cx, double>(M, t, yc.data(), ny, p.data(), s.data(), true, wk, dy.data());
                      for (int j = 0; j < ny; ++j) jac[static_cast<size_t>(j) * ny + i] = dy[j].im / step;
                  }
              }
              return out;
          },
          "model"_a, "t"_a, "y"_a, "phases"_a, "signs"_a,
          "Exact Jacobian d(dy/dt)/dy of the phases by the complex step (one complex evaluation per column).");

    m.def("jvp",
          [](const PyModel& pm, double t, const Array& y, const Array& v, const IntArray& ph, const IntArray& sg,
             bool right, const std::string& method) {
              const Model& M = pm.m;
              const Layout L = layout_of(M, y, "y");
              const int nd = L.nd;
              if (v.ndim() != 1 || static_cast<long>(v.shape(0)) != nd)
                  fail("v has shape " + shape_of(v) + ": must be (" + std::to_string(nd) + ",)");
              std::vector<int> p, s;
              phases_of(M, ph, sg, p, s);
              if (method != "auto" && method != "linear" && method != "complex")
                  fail("method must be 'auto', 'linear' or 'complex'");
              if (method == "linear" && M.S != 1) fail("the tangent-linear form exists for one slider only");
              std::vector<double> dy(L.size);
              Work<double> wk(M);
              evaluate<double, double>(M, t, y.data(), L.size, p.data(), s.data(), right, wk, dy.data());
              double* out;
              Out res = new_array({static_cast<size_t>(nd)}, &out);
              if (method == "complex" && M.S == 1) {
                  const double scale = norm_inf(v.data(), nd);
                  if (scale == 0.0) return res;
                  const double h = CSTEP / scale;
                  ComplexScratch cx(M, nd);
                  for (int i = 0; i < nd; ++i) cx.y[i] = Cx(y.data()[i], h * v.data()[i]);
                  evaluate<Cx, double>(M, t, cx.y.data(), nd, p.data(), s.data(), right, cx.wk, cx.dy.data());
                  for (int i = 0; i < nd; ++i) out[i] = cx.dy[i].im / h;
                  return res;
              }
              ComplexScratch cx(M, nd);
              jvp(M, t, y.data(), v.data(), nd, p.data(), s.data(), right, wk, cx, out);
              return res;
          },
          "model"_a, "t"_a, "y"_a, "v"_a, "phases"_a, "signs"_a, "right"_a = true, "method"_a = "auto",
          "J(t, y) v over the dynamic state: 'linear' the one-slider tangent-linear form, 'complex' the "
          "complex step, 'auto' what the integrator uses.");

    m.def("kinetic_friction",
          [](const PyModel& pm, double radius, int sign, double v) {
              if (sign != 1 && sign != -1) fail("sign must be +1 or -1");
              return kinetic_friction<double>(pm.m.fr, radius, sign, v);
          },
          "model"_a, "radius"_a, "sign"_a, "v"_a,
          "Kinetic friction coefficient at relative speed v [rad/s] on track radius [m] in slip with sign.");

    m.def("unslaved",
          [](const PyModel& pm, double t, const Array& y, const IntArray& ph, const IntArray& sg, const Array& V) {
              const Model& M = pm.m;
              const Layout L = layout_of(M, y, "y");
              std::vector<int> p, s;
              phases_of(M, ph, sg, p, s);
              if (V.ndim() != 2 || static_cast<long>(V.shape(1)) != L.nd)
                  fail("tangent vectors have shape " + shape_of(V) + ": must be (k, " + std::to_string(L.nd) + ")");
              const size_t k = V.shape(0);
              double* out;
              Out res = new_array({k, static_cast<size_t>(L.nd)}, &out);
              unslaved(M, t, y.data(), p.data(), s.data(), V.data(), static_cast<int>(k), out);
              return res;
          },
          "model"_a, "t"_a, "y"_a, "phases"_a, "signs"_a, "vectors"_a,
          "Tangent vectors (rows) with the slaved rows filled in: z, zdot of a slider in contact follow the "
          "disc's surface under it.");

    m.def("free_mask",
          [](const PyModel& pm, const IntArray& ph) {
              const Model& M = pm.m;
              const std::vector<int> p = phases_of(M, ph);
              const int nd = 2 * (M.n + 2 * M.S);
              std::vector<double> mask(nd, 1.0);
              slave(M, p.data(), mask.data());
              nb::object np = nb::module_::import_("numpy");
              double* out;
              Out res = new_array({static_cast<size_t>(nd)}, &out);
              std::memcpy(out, mask.data(), sizeof(double) * nd);
              return np.attr("asarray")(res).attr("astype")(np.attr("bool_"));
          },
          "model"_a, "phases"_a, "Mask of the coordinates that are free in the phases.");

    m.def("single_impact",
          [](const PyModel& pm, const Array& y, int j) {
              const Model& M = pm.m;
              const Layout L = layout_of(M, y, "y");
              if (j < 0 || j >= M.S) fail("slider index out of range");
              std::vector<int> p(M.S, SEPARATION), s(M.S, 1);
              double* out;
              Out res = new_array({static_cast<size_t>(L.size)}, &out);
              std::memcpy(out, y.data(), sizeof(double) * L.size);
              std::vector<double> dy(L.size);
              Work<double> wk(M);
              evaluate<double, double>(M, 0.0, out, L.size, p.data(), s.data(), true, wk, dy.data());
              single_impact(M, j, out, L.size, wk);
              return res;
          },
          "model"_a, "y"_a, "slider"_a,
          "The state after the plastic impact of the slider alone (paper Eqs. 47-56).");

    m.def("solve_lcp",
          [](const Array& dmat, const Array& gam, nb::ndarray<const bool, nb::ndim<1>, nb::c_contig> forced) {
              const long mm = static_cast<long>(gam.ndim() == 1 ? gam.shape(0) : -1);
              if (mm < 1 || mm > 30) fail("gam must be a vector of 1 to 30 values");
              need_shape(dmat, "dmat", {mm, mm});
              if (static_cast<long>(forced.shape(0)) != mm) fail("forced must have one value per contact");
              const int m2 = static_cast<int>(mm);
              std::vector<double> D(dmat.data(), dmat.data() + dmat.size());
              std::vector<double> g(gam.data(), gam.data() + m2), lam(m2);
              std::vector<char> f(m2);
              for (int i = 0; i < m2; ++i) f[i] = forced.data()[i];
              const std::vector<double> w = solve_lcp(D, g, f, lam, m2);
              double *pw, *pl;
              Out ow = new_array({static_cast<size_t>(m2)}, &pw);
              Out ol = new_array({static_cast<size_t>(m2)}, &pl);
              for (int i = 0; i < m2; ++i) {
                  pw[i] = w[i];
                  pl[i] = lam[i];
              }
              return nb::make_tuple(ow, ol);
          },
          "dmat"_a, "gam"_a, "forced"_a,
          "(w, lam) solving lam >= 0, w = gam + D lam >= 0, lam.w = 0 (forced contacts bilateral).");

    m.def("floor_dopri_linear",
          [](nb::ndarray<const int64_t, nb::ndim<1>, nb::c_contig> indptr,
             nb::ndarray<const int64_t, nb::ndim<1>, nb::c_contig> indices,
             nb::ndarray<const double, nb::ndim<1>, nb::c_contig> data, const Array& u, const Array& v,
             const Array& y0, double t_final, double rtol, double atol) {
              const long n = static_cast<long>(y0.ndim() == 1 ? y0.shape(0) : -1);
              if (n < 1) fail("y0 must be a non-empty vector");
              if (static_cast<long>(indptr.shape(0)) != n + 1) fail("indptr must have n + 1 entries");
              const int64_t* ip = indptr.data();
              if (ip[0] != 0) fail("indptr must start at 0");
              for (long i = 0; i < n; ++i)
                  if (ip[i + 1] < ip[i]) fail("indptr must not decrease");
              if (ip[n] != static_cast<int64_t>(indices.shape(0)) || indices.shape(0) != data.shape(0))
                  fail("indices and data must have indptr[-1] entries");
              for (size_t p = 0; p < indices.shape(0); ++p)
                  if (indices.data()[p] < 0 || indices.data()[p] >= n) fail("an index is out of range");
              if (u.ndim() != 2 || v.ndim() != 2 || u.shape(0) != v.shape(0) ||
                  static_cast<long>(u.shape(1)) != n || static_cast<long>(v.shape(1)) != n)
                  fail("u and v must have shape (rank, n)");
              if (!(t_final >= 0 && std::isfinite(t_final) && rtol > 0 && atol > 0))
                  fail("t_final, rtol and atol must be positive and finite");
              LinearOperator op{ip, indices.data(),
                                data.data(), u.data(), v.data(), static_cast<int>(u.shape(0)), static_cast<int>(n)};
              std::vector<double> y(y0.data(), y0.data() + n);
              nb::gil_scoped_release release;
              return floor_dopri_linear(op, y.data(), t_final, rtol, atol);
          },
          "indptr"_a, "indices"_a, "data"_a, "u"_a, "v"_a, "y0"_a, "t_final"_a, "rtol"_a, "atol"_a,
          "Accepted steps of DOPRI5 with the integrator's step control on y' = (B + U^T V) y over "
          "[0, t_final], B in CSR form: the floor of the cost per step (benchmarks/floor.py).");

    nb::class_<PyIntegrator>(m, "Integrator",
        "One integration of a model, advanced call by call; its whole state is kept between calls.")
        .def("__init__",
             [](PyIntegrator* self, const PyModel& pm, const Array& y0, const IntArray& phases, double t_final,
                double rtol, double atol, double max_step, double out_dt, int64_t n_out, double max_switches,
                double zeno_dt, double zeno_count, int64_t stop_mask, const Array& breaks) {
                 const Model& M = pm.m;
                 const Layout L = layout_of(M, y0, "y0");
                 need_finite(y0, "y0");
                 const std::vector<int> p = phases_of(M, phases);
                 if (!(std::isfinite(t_final) && t_final >= 0)) fail("t_final must be finite and >= 0");
                 if (!(rtol > 0 && std::isfinite(rtol))) fail("rtol must be positive and finite");
                 if (!(atol > 0 && std::isfinite(atol))) fail("atol must be positive and finite");
                 if (!(max_step >= 0)) fail("max_step must be >= 0 (0: none)");
                 if (!(out_dt > 0)) fail("out_dt must be positive (inf: no samples)");
                 const long most = static_cast<long>(MAX_OUTPUT / (L.size + 4 * M.S + 1));
                 if (n_out < 0 || n_out > most)
                     fail("n_out must be from 0 to " + std::to_string(most) + " samples");
                 if (breaks.ndim() != 1) fail("breaks must be a vector");
                 need_finite(breaks, "breaks");
                 std::vector<double> br(breaks.data(), breaks.data() + breaks.size());
                 for (size_t i = 1; i < br.size(); ++i)
                     if (!(br[i] > br[i - 1])) fail("breaks must increase");
                 Control c;
                 c.rtol = rtol;
                 c.atol = atol;
                 c.max_step = max_step;
                 c.t_final = t_final;
                 c.out_dt = out_dt;
                 c.max_switches = max_switches;
                 c.zeno_dt = zeno_dt;
                 c.zeno_count = zeno_count;
                 c.stop_mask = stop_mask;
                 new (self) PyIntegrator{Integrator(M, std::vector<double>(y0.data(), y0.data() + L.size), p, c,
                                                    n_out, br), nb::none(), nb::none()};
                 nb::object empty = nb::module_::import_("numpy").attr("empty");
                 self->out_y = empty(nb::make_tuple(n_out, L.size));
                 self->out_aux = empty(nb::make_tuple(n_out, self->it.cols.width()));
                 using Rows = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
                 self->it.attach_output(nb::cast<Rows>(self->out_y).data(),
                                        nb::cast<Rows>(self->out_aux).data());
             },
             "model"_a, "y0"_a, "phases"_a, nb::kw_only(), "t_final"_a, "rtol"_a, "atol"_a, "max_step"_a = 0.0,
             "out_dt"_a = INFINITY, "n_out"_a = 0, "max_switches"_a = 1e18, "zeno_dt"_a = 1e-10,
             "zeno_count"_a = 1000.0, "stop_mask"_a = 0, "breaks"_a)
        .def("advance",
             [](PyIntegrator& self, double target, int64_t call_steps) {
                 PyIntegrator::Guard g(self.busy);
                 nb::gil_scoped_release release;
                 self.it.ctl.call_steps = call_steps;
                 return self.it.advance(target);
             },
             "target"_a, "call_steps"_a = 0,
             "Integrate until t >= target, the end, a failure, a nearly full event log, or call_steps steps "
             "tried (<= 0: no bound); returns the status. The GIL is released meanwhile.")
        .def("take_events",
             [](PyIntegrator& self) {
                 PyIntegrator::Guard g(self.busy);
                 const size_t m2 = self.it.log.items.size();
                 double* t;
                 int64_t* r;
                 Out times = new_array({m2}, &t);
                 auto rows = new_int_array({m2, 4}, &r);
                 for (size_t i = 0; i < m2; ++i) {
                     const Event& e = self.it.log.items[i];
                     t[i] = e.t;
                     r[4 * i] = e.kind;
                     r[4 * i + 1] = e.from;
                     r[4 * i + 2] = e.to;
                     r[4 * i + 3] = e.slider;
                 }
                 self.it.log.clear();
                 return nb::make_tuple(times, rows);
             },
             "(times, rows): the switches since the last call, rows of (kind, from, to, slider); the log is "
             "emptied.")
        .def_prop_rw("event_capacity", [](const PyIntegrator& s) { return s.it.event_capacity; },
                     [](PyIntegrator& s, int c) {
                         if (c < 4 * s.it.M.S + 8) fail("event_capacity too small");
                         s.it.event_capacity = c;
                     })
        .def("set_tangents",
             [](PyIntegrator& self, const Array& V) {
                 PyIntegrator::Guard g(self.busy);
                 const int nd = self.it.L.nd;
                 if (V.ndim() != 2 || static_cast<long>(V.shape(1)) != nd || V.shape(0) < 1)
                     fail("tangent vectors have shape " + shape_of(V) + ": must be (k, " + std::to_string(nd) +
                          "), rows over the dynamic state");
                 need_finite(V, "tangent vectors");
                 self.it.set_tangents(V.data(), static_cast<int>(V.shape(0)));
             },
             "vectors"_a, "Carry tangent vectors (rows over the dynamic state) from the current state on.")
        .def_prop_ro("has_tangents", [](const PyIntegrator& s) { return static_cast<bool>(s.it.tan); })
        .def("tangents",
             [](PyIntegrator& self, bool slaved) {
                 PyIntegrator::Guard g(self.busy);
                 Integrator& I = self.it;
                 if (!I.tan) fail("no tangent vectors are carried: call set_tangents first");
                 const int nd = I.L.nd, kv = I.tan->k;
                 double* out;
                 Out res = new_array({static_cast<size_t>(kv), static_cast<size_t>(nd)}, &out);
                 if (slaved)
                     unslaved(I.M, I.clk.t, I.y.data(), I.ph.data(), I.sg.data(), I.tan->V.data(), kv, out);
                 else
                     std::memcpy(out, I.tan->V.data(), sizeof(double) * kv * nd);
                 return res;
             },
             "slaved"_a = true,
             "The tangent vectors (rows); with slaved, z and zdot of a slider in contact are filled in as the "
             "output carries them, else zero as integrated.")
        .def("rhs",
             [](PyIntegrator& self) {
                 const Integrator& I = self.it;
                 double* out;
                 Out res = new_array({static_cast<size_t>(I.L.nd)}, &out);
                 std::memcpy(out, I.k.data(), sizeof(double) * I.L.nd);
                 return res;
             },
             "The current phases' right-hand side at the current state (dynamic part).")
        .def_prop_ro("t", [](const PyIntegrator& s) { return s.it.clk.t; })
        .def_prop_ro("h", [](const PyIntegrator& s) { return s.it.clk.h; })
        .def_prop_ro("status", [](const PyIntegrator& s) { return s.it.cnt.status; })
        .def_prop_ro("started", [](const PyIntegrator& s) { return s.it.cnt.started; })
        .def_prop_ro("paused", [](const PyIntegrator& s) { return s.it.cnt.paused; })
        .def_prop_ro("n_samples", [](const PyIntegrator& s) { return s.it.cnt.out_next; })
        .def_prop_ro("n_events", [](const PyIntegrator& s) { return s.it.log.size(); })
        .def_prop_ro("stats",
                     [](const PyIntegrator& s) {
                         const Counters& c = s.it.cnt;
                         nb::dict d;
                         d["steps"] = c.steps;
                         d["rejected"] = c.rejected;
                         d["rhs"] = c.rhs;
                         d["rhs_events"] = c.eval_events;
                         d["switches"] = c.switches;
                         d["samples"] = c.out_next;
                         return d;
                     },
                     "Counters: accepted and rejected steps, right-hand sides (those to locate events), "
                     "switches, samples written.")
        .def_prop_ro("switches", [](const PyIntegrator& s) { return s.it.cnt.switches; })
        .def_prop_ro("steps_tried", [](const PyIntegrator& s) { return s.it.cnt.steps + s.it.cnt.rejected; })
        .def("take_peak",
             [](PyIntegrator& s) {
                 const double p = s.it.clk.w_peak;
                 s.it.clk.w_peak = 0.0;
                 return p;
             },
             "The largest |w| [m] under the sliders at the samples written since the last call (nan if any "
             "was not finite), and start again.")
        .def_prop_ro("y",
                     [](PyIntegrator& s) {
                         double* out;
                         Out res = new_array({s.it.y.size()}, &out);
                         std::memcpy(out, s.it.y.data(), sizeof(double) * s.it.y.size());
                         return res;
                     },
                     "A copy of the state (with the energy accumulators, if any).", nb::rv_policy::automatic)
        .def_prop_ro("ph",
                     [](PyIntegrator& s) {
                         int64_t* out;
                         auto res = new_int_array({s.it.ph.size()}, &out);
                         for (size_t j = 0; j < s.it.ph.size(); ++j) out[j] = s.it.ph[j];
                         return res;
                     },
                     "A copy of every slider's phase.", nb::rv_policy::automatic)
        .def_prop_ro("sg",
                     [](PyIntegrator& s) {
                         int64_t* out;
                         auto res = new_int_array({s.it.sg.size()}, &out);
                         for (size_t j = 0; j < s.it.sg.size(); ++j) out[j] = s.it.sg[j];
                         return res;
                     },
                     "A copy of every slider's slip sign.", nb::rv_policy::automatic)
        .def_prop_ro("out_y", [](PyIntegrator& s) { return s.out_y; },
                     "The state samples (n_out, size), a numpy array the integrator writes into; "
                     "rows past n_samples are not written.")
        .def_prop_ro("out_aux", [](PyIntegrator& s) { return s.out_aux; },
                     "Per-sample columns (n_out, 4 S + 1), as out_y: N_j, f_j, phase_j, w_j, then "
                     "Omega.");
}
