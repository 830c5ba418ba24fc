// Dormand-Prince 5(4) coefficients and its fourth-order dense output (Hairer's DOPRI5).
//
// J. R. Dormand, P. J. Prince, "A family of embedded Runge-Kutta formulae",
// J. Comput. Appl. Math. 6 (1980) 19-26. E. Hairer, S. P. Norsett, G. Wanner,
// "Solving Ordinary Differential Equations I", 2nd ed., Springer 1993, II.5-II.6.
#pragma once

namespace fivdisc {
namespace dp5 {

inline constexpr double C[7] = {0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0};
inline constexpr double A[7][6] = {
    {0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0},
    {44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0},
    {19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0},
    {9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0},
    {35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0},
};
// Fifth-order weights (the last row of A: first same as last) minus fourth-order weights.
inline constexpr double E[7] = {71.0 / 57600.0, 0.0, -71.0 / 16695.0, 71.0 / 1920.0,
                                -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0};
// Dense-output weights of the fifth interpolation coefficient.
inline constexpr double D[7] = {
    -12715105075.0 / 11282082432.0, 0.0, 87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0};

// Step-size control (PI, Gustafsson): exponents 1/5 - 0.75 beta and beta.
inline constexpr double BETA = 0.04;
inline constexpr double EXPO1 = 0.2 - 0.75 * BETA;

// Continuous-extension coefficients rc (5 rows of n, row-major) of one step from y0 to y1
// with stages k (7 rows of stride kstride).
inline void dense_coefficients(const double* y0, const double* y1, const double* k, int kstride,
                               double h, double* rc, int n) {
    for (int i = 0; i < n; ++i) {
        const double ydiff = y1[i] - y0[i];
        const double bspl = h * k[i] - ydiff;
        rc[i] = y0[i];
        rc[n + i] = ydiff;
        rc[2 * n + i] = bspl;
        rc[3 * n + i] = ydiff - h * k[6 * kstride + i] - bspl;
        double acc = 0.0;
        for (int st = 0; st < 7; ++st) acc += D[st] * k[st * kstride + i];
        rc[4 * n + i] = h * acc;
    }
}

// Coordinate i at fraction theta of the step.
inline double dense_one(const double* rc, int n, double theta, int i) {
    const double th1 = 1.0 - theta;
    return rc[i] + theta * (rc[n + i] + th1 * (rc[2 * n + i] + theta * (rc[3 * n + i] + th1 * rc[4 * n + i])));
}

inline void dense_eval(const double* rc, int n, double theta, double* out) {
    for (int i = 0; i < n; ++i) out[i] = dense_one(rc, n, theta, i);
}

}  // namespace dp5
}  // namespace fivdisc
