"""One version everywhere: the package, the library, the program, its files,
the project's CMakeLists.txt, the C header, CITATION.cff and CHANGELOG.md."""
import re

import h5py

import helpers
from conftest import ROOT


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(friction VERSION (\d+\.\d+\.\d+)", text).group(1)


def test_package_version_is_the_projects(friction):
    assert friction.__version__ == project_version()


def test_library_reports_the_packages_version(friction):
    assert friction.library_version() == friction.__version__
    assert friction.api_version() == 2


def test_program_and_its_files_report_it(friction, program, naf_map):
    out = helpers.run([program, "--version"]).stdout.strip().split("\n")
    assert out[0] == f"friction {friction.__version__}"
    # Then what it was built with and chose, one line each.
    fields = {line.split()[0]: line.split(None, 1)[1] for line in out[1:]}
    assert set(fields) == {"revision", "compiler", "MPI", "HDF5", "GSL", "FFTW", "kernels"}, out
    assert "Fortran" in fields["compiler"]
    # The serial program, without MPI, or (where configuration found no serial HDF5) the parallel one.
    serial = fields["HDF5"].endswith("(serial)")
    assert serial or fields["HDF5"].endswith("(parallel)"), out
    assert fields["MPI"].startswith("none") == serial, out
    assert fields["GSL"][0].isdigit() and fields["FFTW"][0].isdigit() and fields["MPI"], out
    with h5py.File(naf_map) as f:
        assert f.attrs["version"].decode() == friction.__version__
    assert friction.load(naf_map).version == friction.__version__


def test_header_macros_agree():
    header = (ROOT / "include" / "friction.h").read_text()
    parts = [re.search(rf"#define FRICTION_VERSION_{p} (\d+)", header).group(1) for p in ("MAJOR", "MINOR", "PATCH")]
    assert ".".join(parts) == project_version()


def test_pyproject_reads_the_one_place():
    text = (ROOT / "python" / "pyproject.toml").read_text()
    assert 'version = {attr = "friction._version.__version__"}' in text
    assert 'dynamic = ["version"]' in text


def test_citation_and_changelog_name_it():
    citation = (ROOT / "CITATION.cff").read_text()
    assert re.search(r"^version: \"?" + re.escape(project_version()) + r"\"?$", citation, re.M)
    assert "Multi-scale simulations of dry friction using Network Simulation Method" in citation
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert re.search(r"^## \[" + re.escape(project_version()) + r"\]", changelog, re.M)
