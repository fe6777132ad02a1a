"""Reading measured friction images: real Bruker files, the other formats, the friction loop's reduction."""
import os
import struct
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT

from friction._image import ImageError, image_from_arrays, read_image

# Beside the repository (as CI lays it out); FRICTION_REALDATA names another place.
REALDATA = Path(os.environ.get("FRICTION_REALDATA", ROOT.parent / "shared" / "realdata"))
# The means the files' README gives (computed by its author, 4 decimals), by setpoint (V).
README = {"jsotres_si.0_00144.spm": (-1.4, 0.0154, 2.9324), "jsotres_si.0_00160.spm": (0.2, 0.0320, 2.7891),
          "jsotres_si.0_00175.spm": (1.7, 0.0419, 2.6404)}
needs_realdata = pytest.mark.skipif(not REALDATA.is_dir(), reason=f"no measured files beside the repository "
                                    f"({REALDATA} is absent)")


@needs_realdata
@pytest.mark.parametrize("name", sorted(README))
def test_a_bruker_file_reduces_to_the_readme_means(name):
    pytest.importorskip("pySPM")
    image = read_image(REALDATA / name, channel="Friction")
    setpoint, friction, offset = README[name]
    assert image.trace.shape == (32, 32) and image.retrace.shape == (32, 32)
    assert image.pixels == (32, 32)
    assert image.size == pytest.approx((20000.0, 20000.0))   # 2 um x 2 um, in angstrom
    assert image.unit == "V" and image.channel == "Friction" and image.format == "bruker"
    assert image.direction == "down"
    assert image.angle == pytest.approx(90.0, abs=1e-3)        # Rotate Ang. 1.5708 rad
    assert image.metadata["setpoint"] == (setpoint, "V")
    assert image.masked == 0
    # The README rounds to 4 decimals: agreement within 1e-4 V is what it can check.
    assert abs(image.mean_friction() - friction) < 1e-4
    assert abs(image.mean_offset() - offset) < 1e-4
    assert image.line_friction().shape == (32,)
    assert np.mean(image.line_friction()) == pytest.approx(image.mean_friction(), rel=1e-12)


@needs_realdata
def test_friction_rises_with_the_setpoint_and_calibrates():
    pytest.importorskip("pySPM")
    images = [read_image(REALDATA / name) for name in sorted(README, key=lambda n: README[n][0])]
    friction = [im.mean_friction() for im in images]
    assert friction[0] < friction[1] < friction[2]
    nn = read_image(REALDATA / "jsotres_si.0_00160.spm", calibration=25.0)
    assert nn.unit == "nN" and nn.mean_friction() == pytest.approx(25.0 * friction[1], rel=1e-12)


@needs_realdata
def test_a_missing_channel_names_the_file_and_the_channels():
    pytest.importorskip("pySPM")
    with pytest.raises(ImageError, match=r"jsotres_si.0_00144.spm: no channel 'Torsion'.*Friction"):
        read_image(REALDATA / "jsotres_si.0_00144.spm", channel="Torsion")


def test_other_formats_are_refused_by_name(tmp_path):
    other = tmp_path / "scan.h5"
    other.write_bytes(b"\x89HDF\r\n")
    with pytest.raises(ImageError, match=r"scan.h5: .h5 is not a format read_image knows"):
        read_image(other)
    fake = tmp_path / "fake.spm"
    fake.write_text("not a microscope's file\n")
    pytest.importorskip("pySPM")
    with pytest.raises(ImageError, match=r"fake.spm: not a Bruker Nanoscope file"):
        read_image(fake)
    with pytest.raises(ImageError, match=r"missing.spm: no such file"):
        read_image(tmp_path / "missing.spm")


def test_numpy_and_text_round_trips(tmp_path):
    rng = np.random.default_rng(3)
    trace, retrace = rng.normal(size=(5, 7)), rng.normal(size=(5, 7))
    np.savez(tmp_path / "scan.npz", trace=trace, retrace=retrace, size=[20.0, 10.0], angle=7.0, unit="nN")
    image = read_image(tmp_path / "scan.npz")
    assert np.array_equal(image.trace, trace) and np.array_equal(image.retrace, retrace)
    assert image.size == (20.0, 10.0) and image.angle == 7.0 and image.unit == "nN"
    np.testing.assert_array_equal(image.friction(), (trace - retrace) / 2)
    np.save(tmp_path / "both.npy", np.stack([trace, retrace]))
    assert np.array_equal(read_image(tmp_path / "both.npy").retrace, retrace)
    np.savetxt(tmp_path / "t.csv", trace, delimiter=",")
    np.savetxt(tmp_path / "r.txt", retrace)
    text = read_image(tmp_path / "t.csv", retrace=tmp_path / "r.txt", size=(20.0, 10.0))
    np.testing.assert_allclose(text.offset(), (trace + retrace) / 2, rtol=1e-15, atol=1e-15)
    with pytest.raises(ImageError, match=r"scan.npz: no array 'fy/trace'"):
        read_image(tmp_path / "scan.npz", channel="fy")
    (tmp_path / "bad.csv").write_text("1,2\nx,y\n")
    with pytest.raises(ImageError, match=r"bad.csv: not a plain-text table"):
        read_image(tmp_path / "bad.csv")


def test_nan_pixels_are_masked_and_counted():
    trace = np.arange(12.0).reshape(3, 4)
    retrace = -trace.copy()
    retrace[1, 2] = np.nan
    image = image_from_arrays(trace, retrace)
    assert image.masked == 1 and not image.mask[1, 2]
    # Line 1's friction is the mean of its three valid pixels (4, 5, 7).
    assert image.line_friction()[1] == pytest.approx((4 + 5 + 7) / 3)
    with pytest.raises(ImageError, match="differ in shape"):
        image_from_arrays(trace, retrace[:2])


def test_gwyddion_round_trip(tmp_path):
    pytest.importorskip("gwyfile")
    from gwyfile.objects import GwyContainer, GwyDataField, GwySIUnit
    trace = np.arange(12.0).reshape(3, 4)
    container = GwyContainer()
    container["/0/data"] = GwyDataField(np.zeros((3, 4)), xreal=2e-9, yreal=1.5e-9)
    container["/0/data/title"] = "Height"
    container["/1/data"] = GwyDataField(trace, xreal=2e-9, yreal=1.5e-9, si_unit_z=GwySIUnit(unitstr="V"))
    container["/1/data/title"] = "Friction"
    container["/2/data"] = GwyDataField(-trace, xreal=2e-9, yreal=1.5e-9)
    container["/2/data/title"] = "Friction (retrace)"
    container.tofile(str(tmp_path / "scan.gwy"))
    image = read_image(tmp_path / "scan.gwy")          # the first lateral channel
    assert image.channel == "Friction" and image.unit == "V"
    assert np.array_equal(image.trace, trace) and np.array_equal(image.retrace, -trace)
    assert image.size == pytest.approx((20.0, 15.0))


def _write_sxm(path, forward, backward, direction="down", angle=10.0):
    """A Nanonis .sxm as the format is laid out: a text header, then per channel the forward
    and the backward pass (the backward in the order scanned), big-endian float32."""
    ny, nx = forward.shape
    header = (":NANONIS_VERSION:\n2\n:SCANIT_TYPE:\n              FLOAT            MSBFIRST\n"
              f":SCAN_PIXELS:\n       {nx}       {ny}\n:SCAN_RANGE:\n           2.000000E-9           1.500000E-9\n"
              f":SCAN_DIR:\n{direction}\n:SCAN_ANGLE:\n            {angle:.3E}\n"
              ":DATA_INFO:\n\tChannel\tName\tUnit\tDirection\tCalibration\tOffset\n"
              "\t14\tZ\tm\tboth\t1.000E+0\t0.000E+0\n\t20\tLFM\tV\tboth\t1.000E+0\t0.000E+0\n\n:SCANIT_END:\n\n\n")
    data = [np.zeros((ny, nx)), np.zeros((ny, nx)), forward, backward]
    with open(path, "wb") as file:
        file.write(header.encode("ascii") + b"\x1a\x04")
        for block in data:
            file.write(struct.pack(f">{block.size}f", *block.ravel()))


def test_nanonis_backward_pass_is_stored_as_scanned(tmp_path):
    pytest.importorskip("pySPM")
    forward = np.arange(12.0).reshape(3, 4)
    scanned_back = -forward[:, ::-1]     # the backward pass runs from the line's end
    _write_sxm(tmp_path / "scan.sxm", forward, scanned_back)
    image = read_image(tmp_path / "scan.sxm", channel="LFM")
    assert np.array_equal(image.trace, forward)
    assert np.array_equal(image.retrace, -forward)       # by position, like the trace
    assert image.angle == pytest.approx(10.0) and image.size == pytest.approx((20.0, 15.0))
    _write_sxm(tmp_path / "up.sxm", forward, scanned_back, direction="up")
    assert np.array_equal(read_image(tmp_path / "up.sxm").trace, forward[::-1])
