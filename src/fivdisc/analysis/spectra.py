"""Spectra of simulated responses (paper section 3.2, Figs. 8-16 and 20-26).

Short-time Fourier transforms show how the frequency content changes while the disc
speed varies; the spectrum of a whole window, with its peak frequencies refined below
the bin width, tells a periodic response (a fundamental and its superharmonics, e.g.
206 Hz) from a quasi-periodic one (combinations of incommensurate frequencies, e.g.
181 Hz and 290.5 Hz).

Every function takes a result :class:`xarray.Dataset` or a :class:`fivdisc.engine.result.Result`;
a variable with a second dimension (``w``: probe, ``q``/``q_dot``: coordinate) is reduced
to one time series by an index along that dimension, ``probe`` (default 0).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import scipy.fft
import xarray as xr

from fivdisc.errors import AnalysisError

__all__ = [
    "AnalysisError",
    "Peaks",
    "Periodicity",
    "Spectrum",
    "as_dataset",
    "classify",
    "dominant_frequency",
    "find_peaks",
    "series",
    "spectrum",
    "stft",
    "time_window",
]

WindowSpec = str | tuple

# Oscillations whose amplitude is below this fraction of the signal's magnitude are
# rounding noise (a response at rest still leaves ~1e-16 relative residue after detrending).
_NOISE_FLOOR = 1e-10


def as_dataset(data: xr.Dataset | object) -> xr.Dataset:
    """Return the dataset of a :class:`~fivdisc.engine.result.Result`, or ``data`` if it is one.

    Raises
    ------
    AnalysisError
        If ``data`` is neither a Dataset nor an object with a ``dataset`` attribute.
    """
    ds = getattr(data, "dataset", data)
    if not isinstance(ds, xr.Dataset):
        raise AnalysisError(
            f"data = {type(data).__name__} object is invalid: "
            "must be an xarray.Dataset or a fivdisc Result"
        )
    return ds


def time_window(data: xr.Dataset | object, t0: float | None = None,
                t1: float | None = None) -> xr.Dataset:
    """The samples of ``data`` with ``t0 <= time <= t1``.

    Parameters
    ----------
    data : xarray.Dataset or Result
        A result with a ``time`` coordinate [s].
    t0, t1 : float, optional
        Window start and end [s]; default the first and last sample.

    Raises
    ------
    AnalysisError
        If the window is empty, reversed or outside the data's time span, or a window is
        asked of a record of one sample (returned whole without one).
    """
    ds = as_dataset(data)
    if "time" not in ds.coords or ds.sizes["time"] < 1:
        raise AnalysisError("data has no time coordinate with samples")
    if ds.sizes["time"] == 1:  # a run of one sample: itself, but no window within it
        if t0 is None and t1 is None:
            return ds
        raise AnalysisError(f"t0, t1 select within a record of one sample (t = "
                            f"{float(ds['time'].values[0]):g} s): leave them out")
    time = ds["time"].values
    lo, hi = float(time[0]), float(time[-1])
    # Half a sample of slack so that windows typed from printed times are not refused.
    slack = 0.5 * (hi - lo) / (time.size - 1)
    start = lo if t0 is None else _finite("t0", t0)
    end = hi if t1 is None else _finite("t1", t1)
    if not lo - slack <= start < hi:
        raise AnalysisError(
            f"t0 = {t0!r} [s] is outside the data: must be in [{lo:g}, {hi:g}) s"
        )
    if not start < end <= hi + slack:
        raise AnalysisError(
            f"t1 = {t1!r} [s] is invalid: must be in ({start:g}, {hi:g}] s (after t0, "
            "within the data)"
        )
    window = ds.sel(time=slice(start, end))
    if window.sizes["time"] < 2:
        raise AnalysisError(
            f"t0 = {start:g} s to t1 = {end:g} s holds {window.sizes['time']} sample(s): "
            "must hold at least 2"
        )
    return window


def series(data: xr.Dataset | object, var: str, probe: int | None = None,
           t0: float | None = None, t1: float | None = None) -> xr.DataArray:
    """One variable as a 1-D time series over ``[t0, t1]``.

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    var : str
        Name of a variable with a ``time`` dimension, e.g. ``"phi"`` [rad] or ``"w"`` [m].
    probe : int, optional
        Index along the variable's second dimension (``probe`` of ``w``, ``coordinate``
        of ``q``); default 0. Must be unset for a variable with time as only dimension.
    t0, t1 : float, optional
        Window [s]; default the whole record.

    Raises
    ------
    AnalysisError
        If ``var`` is not a time series of the data, or ``probe`` is out of range.
    """
    ds = as_dataset(data)
    allowed = sorted(str(v) for v, da in ds.data_vars.items() if "time" in da.dims)
    if var not in allowed:
        raise AnalysisError(f"var = {var!r} is not a time series of the data: "
                            f"must be one of {', '.join(allowed)}")
    da = ds[var]
    others = [d for d in da.dims if d != "time"]
    if not others:
        if probe is not None:
            raise AnalysisError(f"probe = {probe!r} is invalid for var = {var!r}, which has "
                                "only a time dimension: leave probe unset")
    else:
        (dim,) = others
        index = 0 if probe is None else probe
        size = ds.sizes[dim]
        if isinstance(index, bool) or not isinstance(index, int | np.integer) or not (
            0 <= index < size
        ):
            raise AnalysisError(f"probe = {probe!r} is invalid for var = {var!r}: must be an "
                                f"integer index along {dim!r} in [0, {size - 1}]")
        da = da.isel({dim: int(index)})
        if dim not in da.coords:
            # Keep the index as a scalar coordinate so labels can say which series this is.
            da = da.assign_coords({dim: int(index)})
    return time_window(da.to_dataset(name=var), t0, t1)[var]


@dataclass(frozen=True)
class Spectrum:
    """One-sided amplitude spectrum of a windowed, detrended time series.

    Attributes
    ----------
    frequencies : ndarray
        Frequencies [Hz], from 0 to the Nyquist frequency, on a grid ``oversample``
        times finer than the bin width.
    amplitude : ndarray
        Amplitude [units of the variable]: a sine of amplitude A shows a peak of height A.
    resolution : float
        Bin width of the record, sampling rate / number of samples [Hz].
    name : str
        Variable (with probe index, if any) the spectrum is of.
    units : str
        Units of ``amplitude``.
    long_name : str
        Description of the variable.
    window : str or tuple
        The scipy window used as taper.
    floor : float
        Amplitude below which lines count as rounding noise [units].

    See Also
    --------
    spectrum : Makes it.
    find_peaks : Its strongest lines.

    Examples
    --------
    The slider's angle over the last 40 ms of a 50 ms run (the paper's Table 1 case):

    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.05}))
    >>> spec = fivdisc.spectrum(result, "phi", t0=0.01)
    >>> spec.name, spec.units, spec.long_name
    ('phi', 'rad', 'slider circumferential angle')
    >>> print(f"{spec.resolution:.2f} Hz bins, {spec.frequencies.size} frequencies to "
    ...       f"{spec.frequencies[-1]:.0f} Hz")
    24.94 Hz bins, 1621 frequencies to 5000 Hz
    """

    frequencies: np.ndarray
    amplitude: np.ndarray
    resolution: float
    name: str
    units: str
    long_name: str
    window: WindowSpec
    floor: float


@dataclass(frozen=True)
class Peaks:
    """Spectral peaks, strongest first.

    Attributes
    ----------
    frequencies : ndarray
        Refined peak frequencies [Hz].
    amplitudes : ndarray
        Refined peak amplitudes [units].
    resolution : float
        Bin width of the spectrum they come from [Hz].
    units : str
        Units of ``amplitudes``.

    See Also
    --------
    find_peaks : Makes them.
    classify : What they say about the response.

    Examples
    --------
    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.05}))
    >>> peaks = fivdisc.find_peaks(fivdisc.spectrum(result, "phi", t0=0.01))
    >>> len(peaks), peaks.units
    (2, 'rad')
    >>> for f, a in zip(peaks.frequencies, peaks.amplitudes):
    ...     print(f"{f:.1f} Hz: {a:.4f} rad")
    180.6 Hz: 0.0089 rad
    361.1 Hz: 0.0022 rad
    """

    frequencies: np.ndarray
    amplitudes: np.ndarray
    resolution: float
    units: str = ""

    def __len__(self) -> int:
        return int(self.frequencies.size)


@dataclass(frozen=True)
class Periodicity:
    """What the spectral peaks say about the response.

    Attributes
    ----------
    kind : {"periodic", "quasi-periodic", "irregular", "none"}
        ``periodic``: every peak is an integer multiple of one fundamental;
        ``quasi-periodic``: every peak is an integer combination of two or more
        incommensurate generators (at most ``max_generators``); ``irregular``: more
        generators would be needed (a dense spectrum); ``none``: no peaks (a static
        response).
    fundamental : float
        Fundamental frequency f0 [Hz] of a periodic response, else nan.
    frequencies : tuple of float
        The generators [Hz], ascending: ``(f0,)`` if periodic, ``(f1, f2, ...)`` if
        quasi-periodic; for ``irregular``, the first ``max_generators + 1``
        incommensurate lines found.
    orders : ndarray
        ``(len(peaks), len(frequencies))`` integers: peak i is at
        ``abs(orders[i] @ frequencies)``; all zeros for ``irregular``.
    peaks : Peaks
        The peaks classified.
    tol : float
        Tolerance used [Hz].

    See Also
    --------
    classify : Makes it.

    Examples
    --------
    Two lines at 50 Hz and 50 sqrt(2) Hz, incommensurate, in 1 s sampled at 1 kHz:

    >>> import numpy as np
    >>> import xarray as xr
    >>> import fivdisc
    >>> t = np.arange(0.0, 1.0, 1e-3)
    >>> x = 0.5 * np.sin(2 * np.pi * 50 * t) + 0.2 * np.sin(2 * np.pi * 50 * np.sqrt(2) * t)
    >>> data = xr.Dataset({"x": ("time", x)}, coords={"time": t})
    >>> verdict = fivdisc.classify(fivdisc.find_peaks(fivdisc.spectrum(data, "x")))
    >>> verdict.kind, [round(f, 2) for f in verdict.frequencies]
    ('quasi-periodic', [50.0, 70.71])
    >>> print(verdict.orders)  # each peak as a combination of the generators
    [[1 0]
     [0 1]]
    """

    kind: Literal["periodic", "quasi-periodic", "irregular", "none"]
    fundamental: float
    frequencies: tuple[float, ...]
    orders: np.ndarray = field(repr=False)
    peaks: Peaks = field(repr=False)
    tol: float

    @property
    def summary(self) -> str:
        """One line: the kind, the generators and how many peaks they explain."""
        if self.kind == "none":
            return "none: no spectral peaks (e.g. a static response)"
        n = len(self.peaks)
        fit = f"{n} peak{'s' if n != 1 else ''} within {self.tol:.2g} Hz"
        if self.kind == "periodic":
            return f"periodic: f0 = {self.fundamental:.4g} Hz ({fit} of its multiples)"
        gens = ", ".join(f"f{i + 1} = {f:.4g} Hz" for i, f in enumerate(self.frequencies))
        if self.kind == "quasi-periodic":
            return f"quasi-periodic: {gens} ({fit} of their combinations)"
        return f"irregular: more than {len(self.frequencies) - 1} incommensurate lines ({gens})"

    def __str__(self) -> str:
        return self.summary


def _finite(name: str, value: Any) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = np.nan
    if not np.isfinite(number):
        raise AnalysisError(f"{name} = {value!r} is invalid: must be a finite number")
    return number


def _samples(da: xr.DataArray) -> tuple[np.ndarray, float]:
    """Values and sampling rate [Hz] of a uniformly sampled, finite time series."""
    time = da["time"].values
    if time.size < 2:
        raise AnalysisError(f"var = {da.name!r} holds {time.size} sample(s): frequencies need "
                            "at least 2 (a run shorter than its output interval?)")
    step = np.diff(time)
    mean = (time[-1] - time[0]) / (time.size - 1)
    if np.max(np.abs(step - mean)) > 1e-6 * mean:
        raise AnalysisError(f"var = {da.name!r} is not sampled uniformly in time: spectra "
                            "need the constant-rate output of fivdisc.simulate")
    values = np.asarray(da.values, dtype=float)
    bad = ~np.isfinite(values)
    if bad.any():
        raise AnalysisError(
            f"var = {da.name!r} is not finite from t = {time[bad.argmax()]:g} s (a failed "
            "run?): choose t1 before that time"
        )
    return values, 1.0 / mean


def _taper(window: WindowSpec, n: int) -> np.ndarray:
    from scipy import signal

    try:
        # The periodic (DFT-even) form is the one meant for spectral analysis.
        return signal.get_window(window, n, fftbins=True)
    except (TypeError, ValueError) as exc:
        raise AnalysisError(
            f"window = {window!r} is not a scipy.signal window ({exc}): use a name such as "
            "'hann', 'hamming', 'blackman', 'boxcar' or a tuple such as ('kaiser', 8.0)"
        ) from None


def _label(da: xr.DataArray, var: str) -> str:
    extra = [d for d in ("probe", "coordinate") if d in da.coords and da[d].ndim == 0]
    return var + "".join(f"[{d}={da[d].item()}]" for d in extra)


def stft(data: xr.Dataset | object, var: str = "phi", probe: int | None = None,
         window: WindowSpec = "hann", segment: float = 0.05, overlap: float = 0.75,
         t0: float | None = None, t1: float | None = None,
         detrend: bool = True) -> xr.DataArray:
    """Short-time Fourier transform magnitude (the paper's time-frequency plots).

    Only segments lying wholly inside ``[t0, t1]`` are kept, so no zero padding at
    the ends shows up as spurious broadband content.

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    var : str
        Variable, e.g. ``"phi"`` [rad] or ``"w"`` [m].
    probe : int, optional
        Index along the variable's second dimension (see :func:`series`).
    window : str or tuple
        :func:`scipy.signal.get_window` specification of the taper.
    segment : float
        Segment length [s]; the frequency resolution is about 1/segment [Hz].
    overlap : float
        Fraction of a segment shared with the next one, in [0, 1).
    t0, t1 : float, optional
        Time window [s]; default the whole record.
    detrend : bool
        Remove the least-squares straight line of the selected record first, so that
        the offset and drift of the mean (the slider angle's equilibrium) do not swamp
        the lowest bins. The line is fitted to the whole record, not to each segment:
        a per-segment fit would absorb part of each segment's oscillation and leak it
        into the low frequencies (about A / (pi cycles) per segment).

    Returns
    -------
    xarray.DataArray
        Magnitude with dims ``(time, frequency)``: segment centre times [s] and
        frequencies [Hz]; a sine of amplitude A shows as A [units of ``var``].

    Raises
    ------
    AnalysisError
        On an unknown variable, a bad probe, window, segment or overlap, or a time
        window shorter than one segment.

    See Also
    --------
    spectrum : One spectrum of a whole window, finer in frequency, for a stationary
        stretch.
    fivdisc.plots.plot_spectrogram : Draws it.

    Examples
    --------
    The slider's angle in 20 ms segments (50 Hz resolution) overlapping by half: the
    180 Hz stick-slip line stays in the 200 Hz bin after the first segment.

    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.05}))
    >>> spectrogram = fivdisc.stft(result, "phi", segment=0.02, overlap=0.5)
    >>> spectrogram.dims, spectrogram.shape
    (('time', 'frequency'), (4, 101))
    >>> print(spectrogram["time"].values, spectrogram.idxmax("frequency").values)
    [0.01 0.02 0.03 0.04] [150. 200. 200. 200.]
    """
    from scipy import signal


    da = series(data, var, probe, t0, t1)
    values, fs = _samples(da)
    seg = _finite("segment", segment)
    ovl = _finite("overlap", overlap)
    span = values.size / fs
    nperseg = round(seg * fs)
    if nperseg < 4 or nperseg > values.size:
        raise AnalysisError(
            f"segment = {segment!r} [s] is invalid: must be between {4 / fs:g} s (4 samples) "
            f"and the selected record, {span:g} s"
        )
    if not 0.0 <= ovl < 1.0:
        raise AnalysisError(f"overlap = {overlap!r} is invalid: must be in [0, 1)")
    hop = max(1, nperseg - round(ovl * nperseg))
    sft = signal.ShortTimeFFT(_taper(window, nperseg), hop, fs,
                                    fft_mode="onesided2X", scale_to="magnitude")
    p0 = sft.lower_border_end[1]
    p1 = sft.upper_border_begin(values.size)[1]
    if p1 <= p0:
        raise AnalysisError(
            f"segment = {segment!r} [s] leaves no whole segment in the selected record of "
            f"{span:g} s: shorten the segment or widen t0, t1"
        )
    if detrend:
        values = signal.detrend(values, type="linear")
    transform = sft.stft(values, p0, p1)
    times = float(da["time"].values[0]) + sft.t(values.size, p0, p1)
    attrs = da.attrs
    # Scalar coordinates (the probe's index and position) say where the series was taken.
    where = {name: coord for name, coord in da.coords.items() if coord.ndim == 0}
    return xr.DataArray(
        np.abs(transform).T,
        dims=("time", "frequency"),
        coords={
            "time": ("time", times, {"units": "s", "long_name": "segment centre time"}),
            "frequency": ("frequency", sft.f, {"units": "Hz", "long_name": "frequency"}),
            **where,
        },
        name=_label(da, var),
        attrs={
            "units": attrs.get("units", ""),
            "long_name": f"STFT magnitude of {attrs.get('long_name', var)}",
            "window": str(window),
            "segment": seg,
            "overlap": ovl,
        },
    )


def spectrum(data: xr.Dataset | object, var: str, probe: int | None = None,
             t0: float | None = None, t1: float | None = None, window: WindowSpec = "hann",
             detrend: bool = True, oversample: int = 8) -> Spectrum:
    """Amplitude spectrum of one time window.

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    var : str
        Variable, e.g. ``"phi"`` [rad] or ``"w"`` [m].
    probe : int, optional
        Index along the variable's second dimension (see :func:`series`).
    t0, t1 : float, optional
        Time window [s]; default the whole record. Choose a stationary stretch: the
        resolution is 1 / (t1 - t0) [Hz].
    window : str or tuple
        :func:`scipy.signal.get_window` specification of the taper.
    detrend : bool
        Remove the least-squares straight line first.
    oversample : int
        Zero-padding factor (>= 1): the spectrum is evaluated on a grid this many times
        finer than the bin width, which both smooths plots and makes the quadratic peak
        interpolation of :func:`find_peaks` accurate for any window.

    Raises
    ------
    AnalysisError
        On an unknown variable, a bad probe, window, time window or oversample.

    See Also
    --------
    stft : Spectra of short segments over time, for a response that changes (a
        varying disc speed).
    find_peaks : The strongest lines of the spectrum.
    dominant_frequency : The strongest line's frequency alone.

    Examples
    --------
    The slider's angle in the paper's Table 1 case, leaving out the first 10 ms: the
    stick-slip line near 180 Hz and its second harmonic, each a few bins wide.

    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.05}))
    >>> spec = fivdisc.spectrum(result, "phi", t0=0.01)
    >>> strongest = spec.amplitude.argmax()
    >>> print(f"{spec.frequencies[strongest]:.0f} Hz, {spec.amplitude[strongest]:.4f} "
    ...       f"{spec.units}, bins of {spec.resolution:.1f} Hz")
    182 Hz, 0.0089 rad, bins of 24.9 Hz

    A variable with a second dimension takes an index along it: the disc's deflection
    ``w`` [m] at the second probe.

    >>> fivdisc.spectrum(result, "w", probe=1, t0=0.01).name
    'w[probe=1]'
    """
    from scipy import signal

    if isinstance(oversample, bool) or not isinstance(oversample, int | np.integer) or (
        oversample < 1
    ):
        raise AnalysisError(f"oversample = {oversample!r} is invalid: must be an integer >= 1")
    da = series(data, var, probe, t0, t1)
    values, fs = _samples(da)
    if values.size < 8:
        raise AnalysisError(f"t0, t1 select {values.size} samples of {var!r}: a spectrum "
                            "needs at least 8")
    floor = _NOISE_FLOOR * float(np.max(np.abs(values)))
    if detrend:
        values = signal.detrend(values, type="linear")
    taper = _taper(window, values.size)
    nfft = scipy.fft.next_fast_len(int(oversample) * values.size, real=True)
    amplitude = np.abs(scipy.fft.rfft(values * taper, nfft)) * (2.0 / taper.sum())
    # DC and Nyquist have no negative-frequency twin to fold in.
    amplitude[0] /= 2.0
    if nfft % 2 == 0:
        amplitude[-1] /= 2.0
    return Spectrum(
        frequencies=scipy.fft.rfftfreq(nfft, 1.0 / fs),
        amplitude=amplitude,
        resolution=fs / values.size,
        name=_label(da, var),
        units=da.attrs.get("units", ""),
        long_name=da.attrs.get("long_name", var),
        window=window,
        floor=floor,
    )


def find_peaks(spectrum: Spectrum, n: int = 10, min_rel_height: float = 0.05,
               fmin: float = 0.0, fmax: float | None = None) -> Peaks:
    """The strongest spectral lines, with frequency and amplitude refined between bins.

    Each local maximum of the (oversampled) spectrum is refined by fitting a parabola
    to the logarithm of the amplitude at it and its two neighbours. The log of a
    Gaussian window's line shape is exactly a parabola; for other windows the fit is
    accurate because, with oversampling, the three points lie well inside the main
    lobe (about 1e-4 of a bin for Hann with ``oversample=8``).

    Parameters
    ----------
    spectrum : Spectrum
        From :func:`spectrum`.
    n : int
        Largest number of peaks returned (>= 1).
    min_rel_height : float
        Peaks lower than this fraction of the highest one in the band are dropped,
        in (0, 1]. Keep it above the window's highest side lobe (Hann: 0.027,
        Blackman: 0.0014, boxcar: 0.22) so that side lobes are not taken for lines.
    fmin, fmax : float, optional
        Frequency band searched [Hz]; default everything. The lobe of 0 Hz and its
        side lobes (what detrending leaves of the mean and of a slow drift: the spectrum
        up to its first local minimum, then its local maxima as long as they decrease)
        never count as peaks.

    Returns
    -------
    Peaks
        Strongest first.

    Raises
    ------
    AnalysisError
        On a bad ``n``, ``min_rel_height`` or band.

    See Also
    --------
    dominant_frequency : The strongest line's frequency alone, from a result.
    classify : Periodic, quasi-periodic or irregular, from the peaks.

    Examples
    --------
    The stick-slip line of the paper's Table 1 case and its second harmonic, refined
    to a fraction of the 25 Hz bin width:

    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.05}))
    >>> spec = fivdisc.spectrum(result, "phi", t0=0.01)
    >>> peaks = fivdisc.find_peaks(spec)
    >>> print(peaks.frequencies.round(1), peaks.amplitudes.round(4), peaks.units)
    [180.6 361.1] [0.0089 0.0022] rad
    >>> print(fivdisc.find_peaks(spec, fmax=250.0).frequencies.round(1))
    [180.6]
    """
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise AnalysisError(f"n = {n!r} is invalid: must be an integer >= 1")
    rel = _finite("min_rel_height", min_rel_height)
    if not 0.0 < rel <= 1.0:
        raise AnalysisError(f"min_rel_height = {min_rel_height!r} is invalid: must be in (0, 1]")
    freq, amp = spectrum.frequencies, spectrum.amplitude
    lo = _finite("fmin", fmin)
    hi = freq[-1] if fmax is None else _finite("fmax", fmax)
    if not 0.0 <= lo < hi:
        raise AnalysisError(f"fmin = {fmin!r}, fmax = {fmax!r} [Hz] is not a band: need "
                            f"0 <= fmin < fmax (Nyquist {freq[-1]:g} Hz)")
    # The lobe around 0 Hz and its side lobes are what detrending leaves of the mean and
    # of a slow drift: never a line.
    band = (freq >= lo) & (freq <= hi) & (np.arange(freq.size) > _zero_lobe_end(amp))
    empty = Peaks(np.empty(0), np.empty(0), spectrum.resolution, spectrum.units)
    if not band.any():
        return empty
    height = max(rel * float(amp[band].max()), spectrum.floor)
    if height <= 0.0:
        return empty
    from scipy import signal

    index, _ = signal.find_peaks(amp, height=height)
    index = index[band[index]]
    if index.size == 0:
        return empty
    # The amplitudes compared are >= height > 0, so only the neighbours can be 0.
    tiny = np.finfo(float).tiny
    left, mid, right = (np.log(np.maximum(amp[index + k], tiny)) for k in (-1, 0, 1))
    curvature = left - 2.0 * mid + right
    # A flat top (zero curvature) stays where it is: dividing by -inf gives no shift.
    shift = 0.5 * (left - right) / np.where(curvature < 0.0, curvature, -np.inf)
    step = freq[1] - freq[0]
    frequencies = freq[index] + shift * step
    amplitudes = np.exp(mid - 0.25 * (left - right) * shift)
    order = np.argsort(-amplitudes, kind="stable")[:n]
    return Peaks(frequencies[order], amplitudes[order], spectrum.resolution, spectrum.units)


def _zero_lobe_end(amplitude: np.ndarray) -> int:
    """Last index of the lobe of 0 Hz and of its side lobes in a spectrum.

    The lobe ends at the first local minimum above 0 Hz; its side lobes (the window's
    leakage of a mean or a slow drift) are the local maxima after it that keep
    decreasing. The first local maximum that is not lower than the one before it is a
    line of the signal, and ends the search.
    """
    from scipy import signal

    falls = np.flatnonzero((amplitude[1:-1] <= amplitude[:-2])
                           & (amplitude[1:-1] <= amplitude[2:]))
    if falls.size == 0:
        return amplitude.size - 1
    end = int(falls[0] + 1)
    previous = float(amplitude[: end + 1].max())
    tops, _ = signal.find_peaks(amplitude)
    for top in tops[tops > end]:
        if amplitude[top] >= previous:
            break
        previous, end = float(amplitude[top]), int(top)
    return end


def _combinations(count: int, max_order: int) -> np.ndarray:
    """Nonzero integer vectors with entries in [-max_order, max_order], lowest order first."""
    grid = np.array(list(itertools.product(range(-max_order, max_order + 1), repeat=count)))
    grid = grid[np.any(grid != 0, axis=1)]
    return grid[np.argsort(np.abs(grid).sum(axis=1), kind="stable")]


def _explain(frequency: float, generators: list[float], tol: float,
             combos: np.ndarray) -> np.ndarray | None:
    """Lowest-order integer vector m with |m @ generators| within tol of frequency."""
    values = combos @ np.asarray(generators)
    error = np.abs(np.abs(values) - frequency)
    hits = np.flatnonzero(error <= tol)
    if hits.size == 0:
        return None
    best = hits[0]
    return combos[best] * (1 if values[best] > 0 else -1)


def classify(peaks: Peaks, tol: float | None = None, max_order: int = 4,
             max_generators: int = 3) -> Periodicity:
    """Periodic, quasi-periodic, irregular or no response, from its spectral peaks.

    The response is periodic if, for a fundamental f0 = (lowest peak) / m with
    m <= ``max_order``, every peak lies within ``tol`` of a multiple of f0 (f0 is
    then refitted by least squares; the largest such f0 is taken). Fundamentals below
    20 ``tol`` are not tried: any line lies within ``tol`` of a multiple of f0 with
    chance 2 ``tol`` / f0, so so low a fundamental would fit nearly any set of lines.
    Otherwise the peaks
    are visited strongest first and each one that is no integer combination
    ``sum(m_k f_k)``, ``|m_k| <= max_order``, of the generators so far becomes a new
    generator; the generators are finally refitted by least squares to all the peaks
    they explain.

    Parameters
    ----------
    peaks : Peaks
        From :func:`find_peaks`.
    tol : float, optional
        Largest distance [Hz] between a peak and the line it is identified with;
        default a quarter of the bin width. Two frequencies closer than the record can
        resolve are commensurate as far as the data can tell, so a longer record is the
        way to a finer verdict.
    max_order : int
        Largest harmonic order of the lowest line, and largest |m_k| in combinations.
    max_generators : int
        More incommensurate lines than this make the response ``irregular``.

    Raises
    ------
    AnalysisError
        On a bad ``tol``, ``max_order`` or ``max_generators``.

    See Also
    --------
    find_peaks : The peaks classified.

    Examples
    --------
    The stick-slip motion of the paper's Table 1 case, over 40 ms:

    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.05}))
    >>> peaks = fivdisc.find_peaks(fivdisc.spectrum(result, "phi", t0=0.01))
    >>> verdict = fivdisc.classify(peaks)
    >>> print(f"{verdict.kind}, f0 = {verdict.fundamental:.0f} Hz")
    periodic, f0 = 181 Hz

    Lines at 50 Hz and 150 Hz are periodic, at 50 Hz and 50 sqrt(2) Hz quasi-periodic:

    >>> import numpy as np
    >>> import xarray as xr
    >>> t = np.arange(0.0, 1.0, 1e-3)
    >>> for second in (150.0, 50.0 * np.sqrt(2)):
    ...     x = np.sin(2 * np.pi * 50.0 * t) + 0.5 * np.sin(2 * np.pi * second * t)
    ...     data = xr.Dataset({"x": ("time", x)}, coords={"time": t})
    ...     print(fivdisc.classify(fivdisc.find_peaks(fivdisc.spectrum(data, "x"))))
    periodic: f0 = 50 Hz (2 peaks within 0.25 Hz of its multiples)
    quasi-periodic: f1 = 50 Hz, f2 = 70.71 Hz (2 peaks within 0.25 Hz of their combinations)
    """
    for name, value in (("max_order", max_order), ("max_generators", max_generators)):
        if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
            raise AnalysisError(f"{name} = {value!r} is invalid: must be an integer >= 1")
    tolerance = 0.25 * peaks.resolution if tol is None else _finite("tol", tol)
    if tolerance <= 0.0:
        raise AnalysisError(f"tol = {tol!r} [Hz] is invalid: must be > 0")
    freq = np.asarray(peaks.frequencies, dtype=float)
    if freq.size == 0:
        return Periodicity("none", np.nan, (), np.zeros((0, 0), int), peaks, tolerance)

    for m in range(1, max_order + 1):
        f0 = freq.min() / m
        if f0 < 20.0 * tolerance:
            break
        harmonic = np.rint(freq / f0)
        f0 = float(harmonic @ freq / (harmonic @ harmonic))
        harmonic = np.rint(freq / f0)
        if harmonic.min() >= 1 and np.all(np.abs(freq - harmonic * f0) <= tolerance):
            return Periodicity("periodic", f0, (f0,), harmonic.astype(int)[:, None], peaks,
                               tolerance)

    generators: list[float] = []
    for f in freq:
        if generators and _explain(f, generators, tolerance,
                                   _combinations(len(generators), max_order)) is not None:
            continue
        generators.append(float(f))
        if len(generators) > max_generators:
            break
    if len(generators) > max_generators:
        return Periodicity("irregular", np.nan, tuple(sorted(generators)),
                           np.zeros((freq.size, len(generators)), int), peaks, tolerance)

    combos = _combinations(len(generators), max_order)
    orders = np.zeros((freq.size, len(generators)), int)
    for i, f in enumerate(freq):
        found = _explain(f, generators, tolerance, combos)
        if found is not None:
            orders[i] = found
    refined, *_ = np.linalg.lstsq(orders.astype(float), freq, rcond=None)
    if refined.size == 1:
        # Only multiples of the strongest line: periodic after all, its refit missed tol.
        return Periodicity("periodic", float(refined[0]), (float(refined[0]),), orders, peaks,
                           tolerance)
    rank = np.argsort(refined)
    return Periodicity("quasi-periodic", np.nan, tuple(float(g) for g in refined[rank]),
                       orders[:, rank], peaks, tolerance)


def dominant_frequency(data: xr.Dataset | object, var: str = "phi", probe: int | None = None,
                       t0: float | None = None, t1: float | None = None) -> float:
    """Refined frequency [Hz] of the strongest spectral line; nan for a static response.

    Parameters are those of :func:`spectrum`.

    See Also
    --------
    find_peaks : Every strong line, with its amplitude.

    Examples
    --------
    The stick-slip frequency of the paper's Table 1 case [Hz]:

    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.05}))
    >>> print(f"{fivdisc.dominant_frequency(result, 'phi', t0=0.01):.1f}")
    180.6
    """
    peaks = find_peaks(spectrum(data, var, probe, t0, t1), n=1)
    return float(peaks.frequencies[0]) if len(peaks) else float("nan")
