"""The PEP 517 build backend of contactscope's source distribution: maturin's, after a check that
Rust is installed.

Without it, maturin quietly downloads and installs a Rust toolchain (over 1 GB) when no
``cargo`` is on PATH, and on a machine without internet fails at that download with a message
about the download. Here the build stops at once and says what is needed: Rust ≥ 1.88 from
https://rustup.rs, or a binary wheel, which needs no Rust.
"""

import os
import re
import shutil
import subprocess

# maturin reads this before it would install Rust.
os.environ["MATURIN_NO_INSTALL_RUST"] = "1"

import maturin as _maturin  # noqa: E402  (after the environment is set)

#: The oldest Rust the crates build with (Cargo.toml's rust-version).
MIN_RUST = (1, 88)


def _check_rust() -> None:
    wanted = ".".join(map(str, MIN_RUST))
    hint = (f"contactscope's source distribution needs Rust ≥ {wanted} to build "
            f"(https://rustup.rs), or install the binary wheel, which needs none "
            f"(pip install --only-binary :all: contactscope, or contactscope-cli)")
    cargo = shutil.which("cargo")
    if cargo is None:
        raise RuntimeError(f"no cargo on PATH: {hint}")
    try:
        out = subprocess.run([cargo, "--version"], capture_output=True, text=True,
                             check=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        raise RuntimeError(f"`cargo --version` failed ({e}): {hint}") from e
    found = re.search(r"cargo (\d+)\.(\d+)", out)
    if found and (int(found.group(1)), int(found.group(2))) < MIN_RUST:
        raise RuntimeError(f"{out.strip()} is too old: {hint}")


def get_requires_for_build_wheel(config_settings=None):
    _check_rust()
    return _maturin.get_requires_for_build_wheel(config_settings)


def get_requires_for_build_editable(config_settings=None):
    _check_rust()
    return _maturin.get_requires_for_build_wheel(config_settings)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    _check_rust()
    return _maturin.build_wheel(wheel_directory, config_settings, metadata_directory)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    _check_rust()
    return _maturin.build_editable(wheel_directory, config_settings, metadata_directory)


# Metadata and source distributions: as maturin makes them.
get_requires_for_build_sdist = _maturin.get_requires_for_build_sdist
build_sdist = _maturin.build_sdist
prepare_metadata_for_build_wheel = _maturin.prepare_metadata_for_build_wheel
prepare_metadata_for_build_editable = getattr(
    _maturin, "prepare_metadata_for_build_editable", _maturin.prepare_metadata_for_build_wheel)
