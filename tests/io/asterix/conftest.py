"""Fixtures of the ASTERIX tests: libasterix (skip without it), the conformance recording
fetched at test time, and simulated opensky-radars plots."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

import pytest

pytest.importorskip("asterix.generated", reason="libasterix not installed "
                    "(pip install 'mhtrack[asterix]')")

#: The conformance recording: cat_034_048.pcap of the asterix_decoder 0.7.11 sdist (GPL:
#: fetched at test time, never vendored), and its sha256.
SDIST = "asterix_decoder==0.7.11"
MEMBER = "asterix_decoder-0.7.11/asterix/sample_data/cat_034_048.pcap"
PCAP_SHA256 = "7f4e9a37641bfa27022ee95ba52f178e68260c1b7e83d6a0e4720a96b3a2cc3d"
#: sha256 of the sdist itself (PyPI files never change).
SDIST_SHA256 = "3eb28379c576ad09c813f6ed482d1f5e397667814d3baaf8ff13dceec2146426"


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="session")
def conformance_pcap(pytestconfig: pytest.Config) -> Path:
    """cat_034_048.pcap, cached in pytest's cache folder after the first download."""
    cached = Path(pytestconfig.cache.mkdir("asterix")) / "cat_034_048.pcap"
    if cached.is_file() and _sha256(cached) == PCAP_SHA256:
        return cached
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "pip", "download", "--quiet", "--no-deps",
               "--no-binary", ":all:", "--disable-pip-version-check", SDIST, "-d", tmp]
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
        sdists = list(Path(tmp).glob("asterix_decoder-0.7.11.tar.gz"))
        if done.returncode != 0 or not sdists:
            pytest.skip(f"cannot fetch the conformance recording ({SDIST} sdist; offline?): "
                        f"{(done.stderr or done.stdout).strip().splitlines()[-1:]}")
        assert _sha256(sdists[0]) == SDIST_SHA256, f"{sdists[0].name}: unexpected sha256"
        with tarfile.open(sdists[0]) as tar:
            member = tar.extractfile(MEMBER)
            assert member is not None, f"{MEMBER} not in the sdist"
            data = member.read()
    digest = hashlib.sha256(data).hexdigest()
    assert digest == PCAP_SHA256, f"cat_034_048.pcap sha256 {digest} != {PCAP_SHA256}"
    part = cached.with_name(f"{cached.name}.{os.getpid()}")  # xdist workers race: rename
    part.write_bytes(data)
    os.replace(part, cached)
    return cached


@pytest.fixture(scope="session")
def opensky(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``mhtrack simulate opensky-radars --seed 1 --no-attributes``: plots.csv, truth.csv,
    sensors.toml. Positions only: the round trips here check positions and times to the
    LSB, and a plot's flight level would enter its ground range (slant range to ground);
    the attribute items have their own round trip (test_attributes_roundtrip.py)."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    out = tmp_path_factory.mktemp("opensky")
    r = CliRunner().invoke(cli, ["simulate", "opensky-radars", "--seed", "1",
                                 "--no-attributes", "--out", str(out)])
    assert r.exit_code == 0, r.output
    return out


@pytest.fixture(scope="session")
def opensky_head(opensky: Path) -> Path:
    """The first 3 000 plots of :func:`opensky` (about 100 s of three radars)."""
    lines = (opensky / "plots.csv").read_text().splitlines()[:3001]
    path = opensky / "plots_head.csv"
    path.write_text("\n".join(lines) + "\n")
    return path
