// The model the core integrates: the disc's modal coordinates, the sliders, the friction
// law, the speed profile and the switches, as named fields (docs/model.md states the
// equations). Built once from the arrays fivdisc.model.build_model makes (see
// binding.cpp, which checks them first), read-only afterwards.
#pragma once

#include <vector>

namespace fivdisc {

enum Phase : int { SLIP = 0, STICK = 1, SEPARATION = 2 };

// Event kinds (the event table's "kind" column).
enum EventKind : int { EV_STICK = 0, EV_SLIP = 1, EV_REVERSAL = 2, EV_SEPARATION = 3, EV_RECONTACT = 4 };

enum FrictionLaw : int { LAW_EXPONENTIAL = 0, LAW_STRIBECK = 1, LAW_TABLE = 2 };

// One value per modal coordinate i.
struct Disc {
    std::vector<double> sgn;       // +1 cosine (C) coordinate, -1 sine (D) coordinate
    std::vector<double> l;         // nodal diameters, as a number
    std::vector<int> li;           // the same, as an index
    std::vector<double> l2;        // l^2
    std::vector<double> cs, sn;    // 1, 0 for a cosine coordinate; 0, 1 for a sine one
    std::vector<int> partner;      // the other member of a doublet, -1 for l = 0
    std::vector<double> minv;      // 1 / M
    std::vector<double> kd;        // M omega^2
    std::vector<double> ml2;       // M l^2
    std::vector<double> gyr;       // the 2 Omega gyroscopic factor, sgn l M (or the printed sign)
    std::vector<double> omd_fix;   // turns gyr into the dOmega/dt term's factor
    std::vector<double> cdamp;     // 2 zeta omega M
    std::vector<double> cdamp_om;  // its material-frame Omega q_partner coefficient (0: space-fixed)
};

// One value per slider j; the signed ones are sigma_j times the plain value.
struct Sliders {
    std::vector<double> theta, sigma, mass, inertia, kz, cz, kphi, cphi, n0, radius, hh;
    std::vector<double> smass, skz, scz, sn0, shh;
};

// A piecewise cubic: piece k starts at x[k] and is c0 + c1 tau + c2 tau^2 + c3 tau^3 in
// tau = x - x[k] (rows of five numbers: start, c0, c1, c2, c3).
struct Pieces {
    std::vector<double> rows;  // row-major (count, 5)
    int count = 0;
    bool flat = false;  // one piece, constant: 0 = c1 = c2 = c3
    double start(int k) const { return rows[5 * k]; }
    double c(int k, int p) const { return rows[5 * k + 1 + p]; }
};

struct Friction {
    int law = LAW_EXPONENTIAL;
    double mus = 0, mu0 = 0, mu1 = 0, alpha = 0, vs = 0, delta = 0, muv = 0;
    Pieces table;  // the tabulated law's pieces in the sliding speed [m/s]
};

struct Model {
    int n = 0;     // modal coordinates
    int S = 0;     // sliders
    int lmax = 0;  // largest l
    Disc disc;
    Sliders sl;
    std::vector<double> shape;  // (S, n): mode shapes at each slider's track radius
    Friction fr;
    Pieces speed;  // Omega(t) [rad/s]
    double omdot = 1.0;     // 1 keeps the dOmega/dt terms, 0 drops them
    bool impact = true;     // plastic impact at re-contact
    bool damped = false;    // any modal damping
    double min_flight = 0;  // shortest flight resolved [s]

    double shp(int j, int i) const { return shape[static_cast<size_t>(j) * n + i]; }
};

}  // namespace fivdisc
