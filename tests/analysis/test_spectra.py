"""Spectra, peak refinement and periodicity, checked on synthetic signals of known content."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from fivdisc.analysis.spectra import (
    AnalysisError,
    Peaks,
    classify,
    dominant_frequency,
    find_peaks,
    spectrum,
    stft,
)
from fivdisc.engine.result import Result
from fivdisc.errors import FivdiscError

FS = 10_000.0  # the simulator's default output rate [Hz]


def _dataset(phi: np.ndarray, w: np.ndarray | None = None) -> xr.Dataset:
    """A result-like dataset sampled at FS: phi (time) and, optionally, w (time, probe)."""
    time = np.arange(phi.size) / FS
    data = {"phi": ("time", phi, {"units": "rad", "long_name": "slider circumferential angle"})}
    if w is not None:
        data["w"] = (("time", "probe"), w, {"units": "m", "long_name": "disc displacement"})
    return xr.Dataset(data, coords={"time": ("time", time, {"units": "s", "long_name": "time"})})


def _tones(duration: float, lines: list[tuple[float, float]], seed: int = 0) -> np.ndarray:
    """Sum of sines (frequency [Hz], amplitude) with random phases."""
    t = np.arange(round(duration * FS)) / FS
    phases = np.random.default_rng(seed).uniform(0, 2 * np.pi, len(lines))
    return sum(a * np.sin(2 * np.pi * f * t + p) for (f, a), p in zip(lines, phases, strict=True))


@pytest.mark.parametrize("window", ["hann", "hamming", "blackman"])
@pytest.mark.parametrize("frequency", [181.37, 290.5, 1234.89])
def test_off_bin_sine_recovered_far_below_bin_width(window, frequency):
    # 0.5 s gives 2 Hz bins; 181.37 and 1234.89 Hz sit 0.685 and 0.445 bin off the grid,
    # 290.5 Hz a quarter bin.
    ds = _dataset(_tones(0.5, [(frequency, 0.003)]))
    spec = spectrum(ds, "phi", window=window)
    assert spec.resolution == pytest.approx(2.0)
    peaks = find_peaks(spec)
    assert len(peaks) == 1
    # The quadratic fit on the 8x oversampled spectrum errs by ~2e-5 bin (Hann) to
    # ~5e-4 bin (Hamming, whose distant side lobes let the negative-frequency image leak
    # in); 2e-3 bin is 500x finer than the bin yet leaves margin over both.
    assert abs(peaks.frequencies[0] - frequency) < 2e-3 * spec.resolution
    # Same leakage bounds the amplitude error to ~2e-4 relative.
    assert peaks.amplitudes[0] == pytest.approx(0.003, rel=1e-3)
    assert peaks.units == "rad"


def test_spectrum_accepts_result_and_selects_probe():
    w = np.column_stack([_tones(0.4, [(100.0, 1e-4)]), _tones(0.4, [(237.3, 2e-4)])])
    ds = _dataset(_tones(0.4, [(50.0, 1.0)]), w)
    result = Result(ds)
    # Bins are 2.5 Hz; the bound is the accuracy claimed above.
    assert dominant_frequency(result, "w") == pytest.approx(100.0, abs=5e-3)
    assert dominant_frequency(result, "w", probe=1) == pytest.approx(237.3, abs=5e-3)
    spec = spectrum(result, "w", probe=1)
    assert spec.units == "m" and spec.name == "w[probe=1]"


def test_time_window_selects_the_stationary_part():
    # 150 Hz for 0.3 s, then 400 Hz: each half on its own shows only its own tone.
    t = np.arange(round(0.6 * FS)) / FS
    phi = np.where(t < 0.3, np.sin(2 * np.pi * 150.0 * t), 0.5 * np.sin(2 * np.pi * 400.0 * t))
    ds = _dataset(phi)
    assert dominant_frequency(ds, t1=0.3) == pytest.approx(150.0, abs=0.05)
    assert dominant_frequency(ds, t0=0.3) == pytest.approx(400.0, abs=0.05)


def test_two_close_lines_resolved_with_amplitudes():
    # 181 and 190 Hz are 9 bins apart at 1 s: each is outside the other's main lobe
    # (2 bins half width for Hann), so both amplitudes come back within 1 %.
    ds = _dataset(_tones(1.0, [(181.0, 1.0), (190.0, 0.4)]))
    peaks = find_peaks(spectrum(ds, "phi"))
    np.testing.assert_allclose(peaks.frequencies, [181.0, 190.0], atol=0.01)
    np.testing.assert_allclose(peaks.amplitudes, [1.0, 0.4], rtol=0.01)


def test_side_lobes_and_lines_below_threshold_are_not_peaks():
    # Hann side lobes peak at 2.7 % of their line; the default threshold is 5 %.
    ds = _dataset(_tones(1.0, [(300.0, 1.0), (700.0, 0.03)]))
    peaks = find_peaks(spectrum(ds, "phi"))
    np.testing.assert_allclose(peaks.frequencies, [300.0], atol=0.01)
    assert len(find_peaks(spectrum(ds, "phi"), min_rel_height=0.02)) > 1
    low = find_peaks(spectrum(ds, "phi"), fmin=500.0)
    np.testing.assert_allclose(low.frequencies, [700.0], atol=0.01)


def test_harmonics_of_206_hz_are_periodic():
    # Paper Figs. 13-14: fundamental 206 Hz and superharmonics; 1e-5 noise added.
    lines = [(206.0 * k, a) for k, a in zip(range(1, 8), [1, 0.5, 0.3, 0.2, 0.12, 0.08, 0.06],
                                            strict=True)]
    signal = _tones(1.0, lines) + 1e-5 * np.random.default_rng(1).standard_normal(10_000)
    peaks = find_peaks(spectrum(_dataset(signal), "phi"))
    verdict = classify(peaks)
    assert verdict.kind == "periodic"
    # Refined lines are good to ~1e-4 Hz; f0 is their least-squares fit.
    assert verdict.fundamental == pytest.approx(206.0, abs=1e-3)
    assert verdict.frequencies == (verdict.fundamental,)
    np.testing.assert_array_equal(np.sort(verdict.orders[:, 0]), np.arange(1, 8))
    assert "periodic" in verdict.summary and "206" in verdict.summary


def test_missing_fundamental_is_still_periodic():
    # Only 2 f0 ... 5 f0 present: f0 = 206 Hz is the largest common divisor.
    peaks = find_peaks(spectrum(_dataset(_tones(1.0, [(412.0, 1), (618.0, 0.5),
                                                       (824.0, 0.3), (1030.0, 0.2)])), "phi"))
    verdict = classify(peaks)
    assert verdict.kind == "periodic"
    assert verdict.fundamental == pytest.approx(206.0, abs=1e-3)


def test_combinations_of_181_and_290_5_hz_are_quasi_periodic():
    # Paper Figs. 8-9: lines at m f1 + n f2 with f1 = 181 Hz and f2 = 290.5 Hz.
    f1, f2 = 181.0, 290.5
    combos = [(1, 0, 1.0), (0, 1, 0.7), (-1, 1, 0.3), (2, 0, 0.2), (1, 1, 0.15), (0, 2, 0.1),
              (2, -1, 0.08), (-1, 2, 0.06)]
    signal = _tones(1.0, [(m * f1 + n * f2, a) for m, n, a in combos])
    verdict = classify(find_peaks(spectrum(_dataset(signal), "phi")))
    assert verdict.kind == "quasi-periodic"
    assert np.isnan(verdict.fundamental)
    np.testing.assert_allclose(verdict.frequencies, [f1, f2], atol=1e-3)
    # Every peak is identified with the combination that made it.
    lines = np.abs(verdict.orders @ np.array(verdict.frequencies))
    np.testing.assert_allclose(lines, verdict.peaks.frequencies, atol=1e-2)
    assert {tuple(row) for row in verdict.orders} == {(m, n) for m, n, _ in combos}


def test_too_low_a_fundamental_is_not_claimed():
    # Every line is a multiple of 1 Hz, but with 1 Hz bins (tol 0.25 Hz) a random line
    # would be within tol of a multiple of 1 Hz half the time: no evidence of periodicity.
    peaks = Peaks(np.array([181.0, 290.0, 1.0]), np.array([1.0, 0.5, 0.2]), resolution=1.0)
    verdict = classify(peaks)
    assert verdict.kind == "quasi-periodic"
    assert verdict.frequencies == (1.0, 181.0, 290.0)


def test_many_incommensurate_lines_are_irregular():
    lines = [(100.0 * x, 1.0 - 0.1 * i)
             for i, x in enumerate([1.0, np.sqrt(2), np.pi, np.sqrt(7), np.e ** 1.5])]
    verdict = classify(find_peaks(spectrum(_dataset(_tones(1.0, lines)), "phi")))
    assert verdict.kind == "irregular"
    assert len(verdict.frequencies) == 4


def test_static_response_has_no_peaks():
    # A slider at rest: a constant angle with rounding-level wiggle.
    phi = 1e-3 + 1e-19 * np.random.default_rng(2).standard_normal(2000)
    spec = spectrum(_dataset(phi), "phi")
    assert len(find_peaks(spec)) == 0
    assert classify(find_peaks(spec)).kind == "none"
    assert np.isnan(dominant_frequency(_dataset(phi)))


def test_stft_tracks_a_frequency_switch():
    # 200 Hz of amplitude 1 for 0.5 s, then 300 Hz of amplitude 2; 0.05 s segments give
    # 20 Hz bins, on which both tones fall exactly.
    t = np.arange(round(1.0 * FS)) / FS
    phi = np.where(t < 0.5, np.sin(2 * np.pi * 200.0 * t), 2.0 * np.sin(2 * np.pi * 300.0 * t))
    mag = stft(_dataset(phi), "phi", segment=0.05, overlap=0.75)
    assert mag.dims == ("time", "frequency")
    assert mag.attrs["units"] == "rad" and mag["frequency"].attrs["units"] == "Hz"
    assert mag["time"].attrs["units"] == "s"
    # Only whole segments: centres from 0.025 s to 0.975 s in hops of 12.5 ms.
    np.testing.assert_allclose(mag["time"].values[[0, -1]], [0.025, 0.975], atol=1e-9)
    np.testing.assert_allclose(np.diff(mag["time"].values), 0.0125)
    peak = mag["frequency"].values[mag.argmax("frequency").values]
    early, late = mag["time"] < 0.475, mag["time"] > 0.525
    assert np.all(peak[early.values] == 200.0) and np.all(peak[late.values] == 300.0)
    # Magnitude scaling: a bin-centred tone of amplitude A reads A. The record's detrend
    # line absorbs a little of the tones (their projection on a line, ~1e-4 here).
    np.testing.assert_allclose(mag.sel(frequency=200.0)[early].values, 1.0, rtol=1e-3)
    np.testing.assert_allclose(mag.sel(frequency=300.0)[late].values, 2.0, rtol=1e-3)


def test_stft_options_window_and_detrend():
    t = np.arange(round(0.5 * FS)) / FS
    phi = 0.02 + 0.3 * t + np.sin(2 * np.pi * 500.0 * t + 0.4)
    options = {"window": "blackman", "segment": 0.02, "overlap": 0.5, "t0": 0.1, "t1": 0.4}
    mag = stft(_dataset(phi), "phi", **options)
    assert mag.attrs["window"] == "blackman"
    assert mag["frequency"].values[1] == pytest.approx(50.0)  # 1 / segment
    assert mag["time"].values[0] == pytest.approx(0.11) and mag["time"].values[-1] <= 0.39
    assert float(mag.sel(frequency=500.0, method="nearest").min()) == pytest.approx(1.0, rel=1e-3)
    # Detrended, the lowest bins keep at most the ramp's rise within one segment,
    # 0.3 rad/s x 0.02 s = 0.006 rad; not detrended, the offset 0.02 + 0.3 t reads
    # 0.05 to 0.14 rad there.
    low = mag.isel(frequency=slice(0, 3))
    assert float(low.max()) < 0.3 * 0.02 * 1.2
    raw = stft(_dataset(phi), "phi", detrend=False, **options).isel(frequency=slice(0, 3))
    assert float(raw.max()) > 0.1


@pytest.mark.parametrize(
    ("call", "words"),
    [
        (lambda ds: spectrum(ds, "psi"), ["var = 'psi'", "phi"]),
        (lambda ds: spectrum(ds, "phi", probe=0), ["probe = 0", "leave probe unset"]),
        (lambda ds: spectrum(ds, "w", probe=2), ["probe = 2", "[0, 1]"]),
        (lambda ds: spectrum(ds, "phi", t0=0.3), ["t0 = 0.3", "[0, 0.1999"]),
        (lambda ds: spectrum(ds, "phi", t0=0.1, t1=0.05), ["t1 = 0.05"]),
        (lambda ds: spectrum(ds, "phi", window="hanning-ish"), ["window = 'hanning-ish'"]),
        (lambda ds: spectrum(ds, "phi", oversample=0), ["oversample = 0"]),
        (lambda ds: stft(ds, segment=1.0), ["segment = 1.0", "0.2 s"]),
        (lambda ds: stft(ds, overlap=1.0), ["overlap = 1.0", "[0, 1)"]),
        (lambda ds: find_peaks(spectrum(ds, "phi"), n=0), ["n = 0"]),
        (lambda ds: find_peaks(spectrum(ds, "phi"), min_rel_height=2), ["min_rel_height = 2"]),
        (lambda ds: classify(find_peaks(spectrum(ds, "phi")), tol=-1), ["tol = -1"]),
        (lambda ds: spectrum(ds.assign(phi=ds.phi.where(ds.time < 0.1)), "phi"), ["t = 0.1"]),
        (lambda ds: spectrum("result.nc", "phi"), ["data = str"]),
    ],
)
def test_bad_input_names_parameter_and_allowed_values(call, words):
    ds = _dataset(_tones(0.2, [(100.0, 1.0)]), np.zeros((2000, 2)))
    with pytest.raises(AnalysisError) as info:
        call(ds)
    assert isinstance(info.value, FivdiscError) and isinstance(info.value, ValueError)
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message
