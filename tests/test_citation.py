"""CITATION.cff: valid Citation File Format 1.2.0, with the package's version."""

import re
from pathlib import Path

import pytest

import collision_env

CFF = Path(__file__).resolve().parents[1] / "CITATION.cff"


def test_the_citation_has_the_package_version():
    (version,) = re.findall(r'^version: "(.+)"$', CFF.read_text(), flags=re.M)
    assert version == collision_env.__version__


def test_the_citation_is_valid_cff():
    citation = pytest.importorskip("cffconvert").Citation(CFF.read_text())
    citation.validate()  # raises on any departure from the schema of its cff-version
    assert citation.cffobj["cff-version"] == "1.2.0"
