"""Rebuild the generated modules of ``cmdragons/runtime/proto/*.proto``.

``python -m cmdragons.runtime.proto.generate`` writes ``*_pb2.py`` and ``*_pb2.pyi`` beside the
schemas with the protoc that grpcio-tools bundles (the test extra); the generated modules import
each other as ``cmdragons.runtime.proto.<name>_pb2`` because protoc runs from the repository root.
"""

from __future__ import annotations

import sys
from pathlib import Path

__all__ = ["PROTO_DIR", "ROOT", "generate", "schemas"]

PROTO_DIR = Path(__file__).resolve().parent
ROOT = PROTO_DIR.parents[2]


def schemas() -> list[Path]:
    """The schema files, in name order."""
    return sorted(PROTO_DIR.glob("*.proto"))


def generate(out: Path) -> None:
    """Generate every schema's module under ``out`` (``out/cmdragons/runtime/proto/``)."""
    from grpc_tools import protoc  # the test extra: only who regenerates needs it

    out.mkdir(parents=True, exist_ok=True)
    args = ["protoc", f"-I{ROOT}", f"--python_out={out}", f"--pyi_out={out}",
            *(str(p.relative_to(ROOT)) for p in schemas())]
    if protoc.main(args) != 0:
        raise RuntimeError("protoc failed on " + " ".join(args[4:]))


if __name__ == "__main__":
    generate(ROOT)
    sys.exit(0)
