"""The compiled closed-form Fourier moments of a piece of flow, shared by the ``exact`` and ``compliant_exact``
loops: the rates and factors of the integrals of e^{lam tau} e^{-j k w t} over a piece, the amplitudes of a
coordinate or an observable along it, and their accumulation into a period's moments (Gauss-Legendre on flows with
rigid-body modes).

Its functions compile :mod:`~vibroimpact.engines.exact_pieces`' kernels into themselves, and are stamped with its
source (:mod:`~vibroimpact.engines.numba_cache`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from vibroimpact.engines.exact_pieces import NONE, YES, piece_state
from vibroimpact.engines.numba_cache import stamp_with_callees

__all__ = ["moment_rates", "coordinate_amplitudes", "weighted_amplitudes", "piece_factors", "moment_integrals", "add_moments", "add_moments_gl"]


# ---------------------------------------------------------------------------------------------------------- moments
@njit(cache=True, error_model="numpy")
def _series(z):
    """(e^z - 1) / z for small z, without cancellation: e^(x+iy) - 1 = expm1(x) cos y - 2 sin^2(y/2) + i e^x sin y."""
    if z == 0.0:  # exact: the constant term of a real harmonic pair, e^{jwt} e^{-jwt}
        return 1.0 + 0j
    x, y = z.real, z.imag
    half = math.sin(0.5 * y)
    return complex(math.expm1(x) * math.cos(y) - 2.0 * half * half, math.exp(x) * math.sin(y)) / z


@njit(cache=True, error_model="numpy")
def moment_rates(lam, omega):
    """The exponents of a piece's components (the eigenvalues, then +-jw for the two halves of the harmonic term) and
    the reciprocals the closed-form integrals divide by: of each pairwise sum, of each rate - jw (0 where the sum
    vanishes: that integral is then taken by its series). Called once per flow when the engine prepares a problem."""
    m = lam.size + 2
    rates = np.empty(m, dtype=np.complex128)
    for k in range(lam.size):  # element by element: an array-to-slice copy compiles numba's shape-error text (~2 s)
        rates[k] = lam[k]
    rates[lam.size], rates[lam.size + 1] = complex(0.0, omega), complex(0.0, -omega)
    inverse = np.zeros((m + 1, m), dtype=np.complex128)  # rows 0..m-1: 1 / (r_k + r_l); row m: 1 / (r_k - jw)
    for k in range(m):
        for l in range(m):
            s = rates[k] + rates[l]
            inverse[k, l] = 1.0 / s if abs(s) > 0.0 else 0.0
        s = rates[k] - complex(0.0, omega)
        inverse[m, k] = 1.0 / s if abs(s) > 0.0 else 0.0
    return rates, inverse


@njit(cache=True, error_model="numpy")
def coordinate_amplitudes(vecs, hrms, f, m, modal, omega, t0, coordinate, amps):
    """Coordinate ``coordinate`` of the piece as sum_k amps_k e^{rates_k (t - t0)} plus a constant: the modal terms
    (their sum is real) and the harmonic Re(Y e^{jwt}) as two conjugate halves."""
    for i in range(m):
        amps[i] = vecs[f, coordinate, i] * modal[i]
    harmonic = hrms[f, coordinate] * complex(math.cos(omega * t0), math.sin(omega * t0))
    amps[m], amps[m + 1] = 0.5 * harmonic, 0.5 * np.conj(harmonic)


@njit(cache=True, error_model="numpy")
def weighted_amplitudes(vecs, hrms, f, m, modal, omega, t0, weights, row, extra, amps):
    """As :func:`coordinate_amplitudes` for minus the observable weights[row] . y + Re(extra e^{jwt}) (the holding force)."""
    harmonic = extra
    for r in range(weights.shape[1]):
        harmonic += weights[row, r] * hrms[f, r]
    for i in range(m):
        acc = 0j
        for r in range(weights.shape[1]):
            acc += weights[row, r] * vecs[f, r, i]
        amps[i] = -acc * modal[i]
    harmonic *= -complex(math.cos(omega * t0), math.sin(omega * t0))
    amps[m], amps[m + 1] = 0.5 * harmonic, 0.5 * np.conj(harmonic)


@njit(cache=True, error_model="numpy")
def piece_factors(rates_all, rinv_all, f, m, omega, a, length, pair, single, fourier, ea, el):
    """E(s) = int_a^{a+L} e^{s u} du = e^{s a} (e^{s L} - 1) / s for every sum of two rates (``pair``), every rate
    (``single``) and every rate - jw (``fourier``; the last entry: the constant's, s = -jw); near s L = 0 by the series.
    Every exponential is a product of the m exponentials e^{r_k a}, e^{r_k L} of this piece (rates of flow f)."""
    for k in range(m):
        ea[k] = np.exp(rates_all[f, k] * a)
        el[k] = np.exp(rates_all[f, k] * length)
    wa = complex(math.cos(omega * a), -math.sin(omega * a))
    wl = complex(math.cos(omega * length), -math.sin(omega * length))
    for k in range(m):
        for l in range(k, m):
            s = rates_all[f, k] + rates_all[f, l]
            growth = ea[k] * ea[l]
            if abs(s) * length >= 0.5:
                pair[k, l] = growth * (el[k] * el[l] - 1.0) * rinv_all[f, k, l]
            else:
                pair[k, l] = growth * length * _series(s * length)
        s = rates_all[f, k]
        single[k] = ea[k] * ((el[k] - 1.0) / s if abs(s) * length >= 0.5 else length * _series(s * length))
        s = rates_all[f, k] - complex(0.0, omega)
        fourier[k] = ea[k] * wa * ((el[k] * wl - 1.0) * rinv_all[f, m, k] if abs(s) * length >= 0.5 else length * _series(s * length))
    s = complex(0.0, -omega)
    fourier[m] = wa * ((wl - 1.0) / s if abs(s) * length >= 0.5 else length * _series(s * length))


@njit(cache=True, error_model="numpy")
def moment_integrals(amps, m, constant, length, pair, single, fourier, phasor, out, row, slot_fourier, slot_square):
    """Add int x e^{-jwt} dt (``phasor`` = e^{-jw t0}) to out[row, slot_fourier] and int x^2 dt to
    out[row, slot_square] (if >= 0) for x = sum_k amps_k e^{rates_k u} + constant (k < m), from the piece's factors."""
    total = constant * fourier[m]
    for k in range(m):
        total += amps[k] * fourier[k]
    out[row, slot_fourier] += total * phasor
    if slot_square < 0:
        return
    square = constant * constant * length + 0j
    for k in range(m):
        square += amps[k] * (2.0 * constant * single[k] + amps[k] * pair[k, k])
        for l in range(k + 1, m):
            square += 2.0 * amps[k] * amps[l] * pair[k, l]
    out[row, slot_square] += square.real


@njit(cache=True, error_model="numpy")
def add_moments(out, row, stuck, lams, vecs, hrms, csts, f, m, modal, omega, t_piece, ta, tb, rates_all, rinv_all, buffers, hold_w, hold_off, hold_har, size, stops):
    """Add the piece's Fourier and square integrals over [ta, tb] to the period's row ``out[row]``, in closed form
    (the motion is a sum of exponentials): each coordinate times e^{-jwt}, the holding force times e^{-jwt} while
    held, each coordinate squared."""
    mm = m + 2
    amps, pair, single, fourier, ea, el = buffers
    a, length = ta - t_piece, tb - ta
    piece_factors(rates_all, rinv_all, f, mm, omega, a, length, pair, single, fourier, ea, el)
    phasor = complex(math.cos(omega * t_piece), -math.sin(omega * t_piece))
    for i in range(size):
        coordinate_amplitudes(vecs, hrms, f, m, modal, omega, t_piece, i, amps)
        moment_integrals(amps, mm, csts[f, i], length, pair, single, fourier, phasor, out, row, i, size + stops + i)
    if stuck >= 0:
        weighted_amplitudes(vecs, hrms, f, m, modal, omega, t_piece, hold_w, stuck, hold_har[stuck], amps)
        constant = hold_off[stuck]
        for r in range(hold_w.shape[1]):
            constant += hold_w[stuck, r] * csts[f, r]
        moment_integrals(amps, mm, -constant, length, pair, single, fourier, phasor, out, row, size + stuck, NONE)


@njit(cache=True, error_model="numpy")
def add_moments_gl(out, row, want_moments, forces, force_rows, subtract, impulses, lams, vecs, hrms, csts, f, m, modal, omega, t_piece, ta, tb, fastest, nodes, weights, force_w, force_off, force_har, size, stops, z0, q1, q2, y):
    """Over [ta, tb] of a piece of a flow with rigid-body (polynomial) terms, by Gauss-Legendre quadrature on chunks
    of at most 2 / (|lambda|max + w) [s] (exact for the polynomial parts, degree <= 4 in the squares; to round-off for
    the exponentials), both loops' integrals in one pass over the nodes: if ``want_moments``, each coordinate's
    Fourier and square integrals into ``out[row]`` (:func:`add_moments`' closed-form ones); for each stop j in the bit
    mask ``forces``, its force F = force_off[i] + Re(force_har[i] e^{jwt}) + force_w[i] . y (row i = force_rows[j]):
    its integral into ``impulses[j]`` and, if ``want_moments``, its Fourier integral into ``out[row, size + j]``
    (subtracted where ``subtract``: the exact engine's rows are minus its holding force)."""
    chunks = max(1, int(math.ceil(fastest * (tb - ta) / 2.0)))
    for c in range(chunks):
        a = ta + (tb - ta) * c / chunks
        b = ta + (tb - ta) * (c + 1) / chunks
        for q in range(nodes.size):
            t = a + (b - a) * nodes[q]
            w = (b - a) * weights[q]
            piece_state(lams, vecs, hrms, csts, f, m, omega, t_piece, modal, t, y, YES, z0, q1, q2)
            phasor = complex(math.cos(omega * t), -math.sin(omega * t))
            if want_moments:
                for i in range(size):
                    out[row, i] += w * y[i] * phasor
                    out[row, size + stops + i] += w * y[i] * y[i]
            for j in range(stops):
                if not (forces >> j) & 1:
                    continue
                i = force_rows[j]
                force = force_off[i] + (force_har[i] * complex(math.cos(omega * t), math.sin(omega * t))).real
                for r in range(y.size):
                    force += force_w[i, r] * y[r]
                impulses[j] += w * force
                if want_moments:
                    if subtract:
                        out[row, size + j] -= w * force * phasor
                    else:
                        out[row, size + j] += w * force * phasor


stamp_with_callees(globals())
