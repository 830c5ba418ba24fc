// The two scalars the right-hand side is compiled for: double, and the complex number of
// the complex step (Squire & Trapp 1998; Martins, Sturdza & Alonso 2003).
//
// The complex type is written out rather than std::complex: its arithmetic is the
// textbook formulas (division by Smith's method, as Python's), with none of the
// inf/nan recovery of C99 Annex G that std::complex's multiplication calls out of line.
// With an imaginary part of 1e-30 times the scale, the real part of every result is the
// real computation's value (the imaginary part's contribution is below rounding), and
// the imaginary part carries the derivative along the perturbation, exact to rounding.
#pragma once

#include <cmath>

namespace fivdisc {

struct Cx {
    double re = 0.0;
    double im = 0.0;
    constexpr Cx() = default;
    constexpr Cx(double r) : re(r), im(0.0) {}  // NOLINT: implicit on purpose
    constexpr Cx(double r, double i) : re(r), im(i) {}
    Cx& operator+=(const Cx& o) { re += o.re; im += o.im; return *this; }
    Cx& operator-=(const Cx& o) { re -= o.re; im -= o.im; return *this; }
    Cx& operator*=(const Cx& o) { *this = Cx(re * o.re - im * o.im, re * o.im + im * o.re); return *this; }
    Cx& operator+=(double o) { re += o; return *this; }
    Cx& operator-=(double o) { re -= o; return *this; }
    Cx& operator*=(double o) { re *= o; im *= o; return *this; }
};

inline Cx operator-(const Cx& a) { return {-a.re, -a.im}; }
inline Cx operator+(const Cx& a, const Cx& b) { return {a.re + b.re, a.im + b.im}; }
inline Cx operator-(const Cx& a, const Cx& b) { return {a.re - b.re, a.im - b.im}; }
inline Cx operator*(const Cx& a, const Cx& b) {
    return {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re};
}
// Smith's division, as Python and numba divide complex numbers.
inline Cx operator/(const Cx& a, const Cx& b) {
    const double br = b.re, bi = b.im;
    if (std::fabs(br) >= std::fabs(bi)) {
        if (br == 0.0) return {NAN, NAN};
        const double ratio = bi / br;
        const double denom = br + bi * ratio;
        return {(a.re + a.im * ratio) / denom, (a.im - a.re * ratio) / denom};
    }
    const double ratio = br / bi;
    const double denom = br * ratio + bi;
    return {(a.re * ratio + a.im) / denom, (a.im * ratio - a.re) / denom};
}
inline Cx operator+(const Cx& a, double b) { return {a.re + b, a.im}; }
inline Cx operator+(double a, const Cx& b) { return {a + b.re, b.im}; }
inline Cx operator-(const Cx& a, double b) { return {a.re - b, a.im}; }
inline Cx operator-(double a, const Cx& b) { return {a - b.re, -b.im}; }
inline Cx operator*(const Cx& a, double b) { return {a.re * b, a.im * b}; }
inline Cx operator*(double a, const Cx& b) { return {a * b.re, a * b.im}; }
inline Cx operator/(const Cx& a, double b) { return {a.re / b, a.im / b}; }
inline Cx operator/(double a, const Cx& b) { return Cx(a) / b; }

inline Cx exp(const Cx& z) {
    const double r = std::exp(z.re);
    return {r * std::cos(z.im), r * std::sin(z.im)};
}
inline Cx cos(const Cx& z) {
    return {std::cos(z.re) * std::cosh(z.im), -(std::sin(z.re) * std::sinh(z.im))};
}
inline Cx sin(const Cx& z) {
    return {std::sin(z.re) * std::cosh(z.im), std::cos(z.re) * std::sinh(z.im)};
}
// z ** p for a real p, by the polar form (Python's algorithm); 0 ** p is 0.
inline Cx pow(const Cx& z, double p) {
    if (p == 0.0) return {1.0, 0.0};
    if (z.re == 0.0 && z.im == 0.0) return {0.0, 0.0};
    const double len = std::pow(std::hypot(z.re, z.im), p);
    const double phase = std::atan2(z.im, z.re) * p;
    return {len * std::cos(phase), len * std::sin(phase)};
}

inline double exp(double x) { return std::exp(x); }
inline double cos(double x) { return std::cos(x); }
inline double sin(double x) { return std::sin(x); }
inline double pow(double x, double p) { return std::pow(x, p); }

// The real part, on which every decision is taken, whatever the scalar.
inline double re(double x) { return x; }
inline double re(const Cx& x) { return x.re; }
inline double im(double) { return 0.0; }
inline double im(const Cx& x) { return x.im; }

// Python's max and min of two numbers: the first unless the second is strictly beyond it
// (so a nan first argument is kept, a nan second one ignored).
inline double pmax(double a, double b) { return b > a ? b : a; }
inline double pmin(double a, double b) { return b < a ? b : a; }

}  // namespace fivdisc
