"""Bad arguments raise ValueError or TypeError saying what was expected, before any C call."""

import numpy as np
import pytest

import mtcore

FILTERS = [mtcore.median_filter1d, mtcore.uniform_filter1d, mtcore.binomial_filter1d]
X = np.zeros((6, 4))


@pytest.fixture(params=FILTERS, ids=lambda f: f.__name__)
def filt(request):
    return request.param


@pytest.mark.parametrize(
    "kwargs,exc,message",
    [
        (dict(size=0), ValueError, r"^size must be in \[1, \d+\] samples( for the binomial filter \(.*\))?, got 0$"),
        (dict(size=-3), ValueError, r"^size must be in \[1, \d+\] samples( for the binomial filter \(.*\))?, got -3$"),
        (dict(size=2.5), TypeError, r"^size must be an integer, got float 2\.5$"),
        (dict(size="3"), TypeError, r"^size must be an integer, got str '3'$"),
        (dict(size=3, mode="edge"), ValueError, "mode must be one of 'reflect'"),
        (dict(size=3, mode=None), ValueError, "got None"),
        (dict(size=3, origin=2), ValueError, r"^origin must be in \[-1, 1\] for size 3, got 2$"),
        (dict(size=4, origin=-3), ValueError, r"^origin must be in \[-2, 1\] for size 4, got -3$"),
        (
            dict(size=3, axis=2),
            np.exceptions.AxisError,
            r"^axis must be in \[-2, 1\] for a 2-dimensional array, got 2$",
        ),
        (
            dict(size=3, axis=-3),
            np.exceptions.AxisError,
            r"^axis must be in \[-2, 1\] for a 2-dimensional array, got -3$",
        ),
        (
            dict(size=3, output=np.zeros((4, 6))),
            ValueError,
            r"^output must be a writeable array of shape \(6, 4\), got shape \(4, 6\)$",
        ),
        (dict(size=3, output=np.complex128), TypeError, "got dtype complex128"),
        (dict(size=3, output="not a dtype"), TypeError, "output must be None, an ndarray or a dtype"),
        (dict(size=3, cval="a"), TypeError, "cval must be a real number, got 'a'"),
        (dict(size=3, cval=None), TypeError, "cval must be a real number, got None"),
        (dict(size=3, axis=0.0), TypeError, r"^axis must be an integer, got float 0\.0$"),
        (dict(size=3, origin="1"), TypeError, r"^origin must be an integer, got str '1'$"),
        (dict(size=3, axis=None), TypeError, r"^axis must be an integer, got None$"),
    ],
)
def test_bad_arguments(filt, kwargs, exc, message):
    with pytest.raises(exc, match=message):
        filt(X, **kwargs)


@pytest.mark.parametrize(
    "value,message",
    [
        (np.zeros(5, np.complex128), "real numbers .* got dtype complex128"),
        (np.array([object(), object()]), "got dtype object"),
        (np.array(["a", "b"]), "got dtype <U1"),
        (np.zeros(4, np.longdouble), "compute in at most float64"),
    ],
)
def test_bad_input_dtypes(filt, value, message):
    if value.dtype == np.longdouble and np.finfo(np.longdouble).bits == 64:
        pytest.skip("longdouble is float64 on this platform")
    with pytest.raises(TypeError, match=message):
        filt(value, 3)


def test_read_only_output(filt):
    out = np.zeros_like(X)
    out.flags.writeable = False
    with pytest.raises(
        ValueError, match=r"^output must be a writeable array of shape \(6, 4\), got a read-only array$"
    ):
        filt(X, 3, output=out)


def test_zero_dimensional_input_has_no_axis(filt):
    with pytest.raises(np.exceptions.AxisError):
        filt(np.float64(3.0), 1)


def test_c_status_codes_map_to_exceptions():
    from mtcore._mtcore import ffi, lib
    from mtcore._status import check

    check(lib.MT_OK, "noop")
    x = np.zeros(4)
    buf = ffi.from_buffer(x)
    cases = [
        (dict(size=0), ValueError),
        (dict(origin=5), ValueError),
        (dict(mode=17), ValueError),
        (dict(dtype=9), TypeError),
        (dict(filter=lib.MT_FILTER_CORRELATE), ValueError),  # correlate without weights
    ]
    for change, exc in cases:
        args = dict(filter=lib.MT_FILTER_MEDIAN, dtype=lib.MT_FLOAT64, size=3, origin=0, mode=0)
        args.update(change)
        status = lib.mt_filter1d(
            args["filter"],
            args["dtype"],
            buf,
            buf,
            1,
            4,
            1,
            0,
            4,
            args["size"],
            args["origin"],
            args["mode"],
            0.0,
            ffi.NULL,
        )
        with pytest.raises(exc, match=r"mt_filter1d: .* \(status -\d\)"):
            check(status, "mt_filter1d")
    with pytest.raises(MemoryError, match="out of memory"):
        check(lib.MT_ENOMEM, "mt_filter1d")
