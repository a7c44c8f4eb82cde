"""Reading a file's bytes whether it is plain, gzip- or bzip2-compressed: :func:`read_maybe_compressed`.

Logs are often distributed compressed (``fr079.clf.bz2``); the text readers take them as they are. The
compression is recognised by the file's first bytes (gzip ``1f 8b``, bzip2 ``BZh``), not by its name. A
compressed stream that ends early (a download or copy cut short) gives the bytes decompressed so far and
a warning; the reader then sees a truncated last line, which the CARMEN reader tolerates.
"""

from __future__ import annotations

import bz2
import logging
import zlib
from pathlib import Path

from slamtrials.errors import FormatError

__all__ = ["read_maybe_compressed", "read_head", "compression_of"]

log = logging.getLogger(__name__)

_GZIP_MAGIC = b"\x1f\x8b"
_BZIP2_MAGIC = b"BZh"


def compression_of(head: bytes) -> str | None:
    """``"gzip"``, ``"bzip2"`` or None (plain), from a file's first bytes."""
    if head.startswith(_GZIP_MAGIC):
        return "gzip"
    if head.startswith(_BZIP2_MAGIC) and len(head) >= 4 and head[3:4] in b"123456789":
        return "bzip2"
    return None


def _decompressor(kind: str):
    # wbits 16 + MAX_WBITS: a gzip header and trailer around a deflate stream
    return zlib.decompressobj(16 + zlib.MAX_WBITS) if kind == "gzip" else bz2.BZ2Decompressor()


def _decompress(path: Path, data: bytes, kind: str) -> bytes:
    """All members of a gzip or bzip2 stream (``cat a.gz b.gz`` is a valid gzip file), decompressed."""
    parts: list[bytes] = []
    rest = data
    while rest:
        engine = _decompressor(kind)
        try:
            parts.append(engine.decompress(rest))
        except (OSError, EOFError, ValueError, zlib.error) as exc:
            member = len(data) - len(rest)  # where the compressed stream that fails starts
            raise FormatError(path, f"not a readable {kind} file ({exc})", offset=member) from None
        if not engine.eof:
            log.warning(
                "%s: the %s stream ends early (file cut short?): read the %d bytes decompressed so far",
                path,
                kind,
                sum(len(p) for p in parts),
            )
            break
        rest = engine.unused_data
        if rest and compression_of(rest[:4]) != kind:
            if rest.strip(b"\x00"):  # trailing zero padding is common; anything else is not ours to guess
                log.warning("%s: %d bytes after the end of the %s stream ignored", path, len(rest), kind)
            break
    return b"".join(parts)


def read_maybe_compressed(path: Path) -> bytes:
    """The bytes of ``path``, decompressed if it is a gzip or bzip2 file.

    Raises
    ------
    FormatError
        The file is missing, a directory or unreadable, or its compressed stream is corrupt.
    """
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise FormatError(path, "no such file") from None
    except IsADirectoryError:
        raise FormatError(path, "is a directory, expected a text file") from None
    except OSError as exc:
        raise FormatError(path, f"cannot read: {exc.strerror or exc}") from None
    kind = compression_of(data[:4])
    return data if kind is None else _decompress(path, data, kind)


def read_head(path: Path, size: int = 1 << 16) -> bytes:
    """About the first ``size`` bytes of ``path``'s (decompressed) content, to tell formats apart; no
    warnings, and a corrupt or short stream simply gives less. (bzip2 gives nothing before its first
    block, up to 900 kB of input, is read.)

    Raises
    ------
    FormatError
        The file is missing, a directory or unreadable.
    """
    try:
        with open(path, "rb") as handle:
            data = handle.read(size)
            kind = compression_of(data[:4])
            if kind is None:
                return data
            engine, out = _decompressor(kind), b""
            try:
                while data and len(out) < size and not engine.eof:
                    out += engine.decompress(data)
                    data = handle.read(size)
            except (OSError, EOFError, ValueError, zlib.error):
                pass
            return out[:size]
    except FileNotFoundError:
        raise FormatError(path, "no such file") from None
    except IsADirectoryError:
        raise FormatError(path, "is a directory, expected a text file") from None
    except OSError as exc:
        raise FormatError(path, f"cannot read: {exc.strerror or exc}") from None
