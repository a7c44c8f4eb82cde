"""Opening a ROS 1 or ROS 2 bag for :mod:`slamtrials.io.rosbag_read`: detection, topics, raw messages.

Which kind of bag a path is, is decided from the path and, failing that, from the file's first bytes:

* a file ending in ``.bag``, or any file starting with ``#ROSBAG V2.0``: ROS 1;
* a folder with ``metadata.yaml`` (ROS 2, MCAP or SQLite storage), a ``.mcap``/``.db3`` file inside such
  a folder (the folder is read), or a folder holding exactly one ``.mcap`` file: ROS 2;
* a bare ``.mcap`` file (no ``metadata.yaml`` beside it): ROS 2, read from the MCAP file alone.

Messages are decoded with the definitions of ROS 1 Noetic and ROS 2 Humble (the standard messages read
here have not changed across distributions). ROS 1 connections carry an md5 of their definition; a
mismatch with Noetic's is reported as a different message type rather than decoded into garbage.
"""

from __future__ import annotations

import importlib
import struct
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from slamtrials.errors import FormatError
from slamtrials.io import ros_messages as rm

__all__ = ["BagSource", "open_bag", "bag_kind", "DECODE_ERRORS"]

_ROS1_MAGIC = b"#ROSBAG V2.0\n"
_MCAP_MAGIC = b"\x89MCAP0\r\n"


def _decode_errors() -> tuple[type[BaseException], ...]:
    from rosbags.rosbag1 import ReaderError as Reader1Error
    from rosbags.rosbag2 import ReaderError as Reader2Error
    from rosbags.serde import SerdeError

    zstd_errors: tuple[type[BaseException], ...] = ()
    for module in ("compression.zstd", "backports.zstd", "zstandard"):  # whichever rosbags decompresses with
        try:
            zstd_errors = (importlib.import_module(module).ZstdError,)
            break
        except (ImportError, AttributeError):
            continue

    # What rosbags raises on damaged input (found by fuzzing plain and compressed bags): its own errors;
    # decoding errors of damaged lengths, offsets and strings (struct, KeyError, UnicodeDecodeError, its
    # internal asserts); decompressor errors (bz2: OSError, lz4: RuntimeError, zstd: ZstdError, EOFError);
    # and MemoryError when a damaged size asks for an impossible buffer.
    return (
        Reader1Error,
        Reader2Error,
        SerdeError,
        *zstd_errors,
        struct.error,
        ValueError,
        IndexError,
        KeyError,
        EOFError,
        OverflowError,
        AssertionError,
        MemoryError,
        RuntimeError,
        OSError,
    )


#: Exceptions that mean "this bag is damaged"; :func:`open_bag` and its users turn them into FormatError.
DECODE_ERRORS = _decode_errors()


@dataclass
class BagSource:
    """An open bag: its topics and a way to iterate over and decode its messages.

    Attributes
    ----------
    path:
        The path the user gave.
    ros:
        1 or 2.
    topics:
        Topic name -> message type (normalised, e.g. ``sensor_msgs/msg/LaserScan``).
    """

    path: Path
    ros: int
    topics: dict[str, str]
    _reader: Any
    _connections: dict[str, list[Any]] = field(default_factory=dict)

    @property
    def kind(self) -> str:
        """``"ROS 1"`` or ``"ROS 2"``, for messages."""
        return f"ROS {self.ros}"

    def topic_list(self) -> str:
        """The topics with their types, for error messages."""
        if not self.topics:
            return "the bag has no topics"
        return "the bag has " + ", ".join(f"{name} ({kind})" for name, kind in sorted(self.topics.items()))

    def messages(self, topics: list[str]) -> Iterator[tuple[str, int, bytes]]:
        """Raw messages of ``topics`` as (topic, bag record time ns, serialised bytes), in record-time order."""
        connections = [c for topic in topics for c in self._connections.get(topic, [])]
        if not connections:
            return
        for connection, timestamp, raw in self._reader.messages(connections=connections):
            yield connection.topic, timestamp, raw

    def decode(self, raw: bytes, msgtype: str) -> Any:
        """Deserialise one message (``TF_MESSAGE_ALIASES`` decode as ``tf2_msgs/msg/TFMessage``)."""
        if msgtype in rm.TF_MESSAGE_ALIASES:
            msgtype = rm.TF_MESSAGE
        store = rm.typestore(self.ros)
        if self.ros == 1:
            return store.deserialize_ros1(raw, msgtype)
        return store.deserialize_cdr(raw, msgtype)

    def check_digest(self, topic: str) -> None:
        """Raise FormatError if a ROS 1 connection of ``topic`` has another definition than Noetic's."""
        if self.ros != 1:
            return
        msgtype = self.topics[topic]
        known = rm.TF_MESSAGE if msgtype in rm.TF_MESSAGE_ALIASES else msgtype
        expected = rm.typestore(1).generate_msgdef(known)[1]
        for connection in self._connections.get(topic, []):
            if connection.digest and connection.digest != expected:
                raise FormatError(
                    self.path,
                    f"topic {topic}: type {msgtype} has md5 {connection.digest}, expected "
                    f"{expected} (a different definition of the message)",
                )


def bag_kind(path: str | Path) -> tuple[int, Path, str]:
    """Classify ``path`` as described in the module docstring.

    Returns
    -------
    (ros, location, storage):
        ``ros`` is 1 or 2; ``location`` is what to open (the file, or the ROS 2 folder); ``storage`` is
        ``"bag"`` (ROS 1), ``"folder"`` (ROS 2 with metadata.yaml) or ``"mcap"`` (a bare MCAP file).

    Raises
    ------
    FormatError
        ``path`` does not exist or is neither kind of bag.
    """
    path = Path(path)
    if path.is_dir():
        if (path / "metadata.yaml").is_file():
            return 2, path, "folder"
        mcaps = sorted(path.glob("*.mcap"))
        if len(mcaps) == 1:
            return 2, mcaps[0], "mcap"
        raise FormatError(path, "not a ROS 2 bag folder: no metadata.yaml (and not exactly one .mcap file)")
    if not path.exists():
        raise FormatError(path, "no such bag file or folder")
    if path.suffix in (".mcap", ".db3") and (path.parent / "metadata.yaml").is_file():
        return 2, path.parent, "folder"
    try:
        with open(path, "rb") as handle:
            head = handle.read(len(_ROS1_MAGIC))
    except OSError as exc:
        raise FormatError(path, f"cannot read the bag ({exc.strerror or exc})") from None
    if path.suffix == ".bag" or head == _ROS1_MAGIC:
        return 1, path, "bag"
    if path.suffix == ".mcap" or head.startswith(_MCAP_MAGIC):
        return 2, path, "mcap"
    raise FormatError(path, "not a ROS bag: expected a ROS 1 .bag file, a ROS 2 bag folder or an .mcap file")


@contextmanager
def open_bag(path: str | Path) -> Iterator[BagSource]:
    """Open the bag at ``path`` (see :func:`bag_kind`) and close it afterwards.

    Raises
    ------
    FormatError
        Not a bag, or a damaged one (truncated, garbled, unindexed); the message names the file.
    """
    path = Path(path)
    ros, location, storage = bag_kind(path)
    reader = _make_reader(ros, location, storage)
    try:
        reader.open()
    except FileNotFoundError as exc:
        raise FormatError(path, f"incomplete {'ROS ' + str(ros)} bag: {exc}") from None
    except DECODE_ERRORS as exc:
        raise FormatError(path, _damaged(ros, exc)) from None
    try:
        try:
            source = _source(path, ros, reader)
        except DECODE_ERRORS as exc:
            raise FormatError(path, _damaged(ros, exc)) from None
        yield source
    finally:
        try:
            reader.close()
        except DECODE_ERRORS:
            pass


def _damaged(ros: int, exc: BaseException) -> str:
    hint = (
        " (a ROS 1 bag cut short can be repaired with 'rosbag reindex')"
        if ros == 1 and "index" in str(exc).lower()
        else ""
    )
    detail = str(exc) or type(exc).__name__
    return f"not a readable ROS {ros} bag, damaged or truncated: {detail}{hint}"


def _make_reader(ros: int, location: Path, storage: str) -> Any:
    if ros == 1:
        from rosbags.rosbag1 import Reader

        return Reader(location)
    if storage == "folder":
        from rosbags.rosbag2 import Reader

        return Reader(location)
    from rosbags.rosbag2.storage_mcap import McapReader

    return McapReader(location)


def _normalise(msgtype: str) -> str:
    parts = msgtype.split("/")
    if len(parts) == 2:  # ROS 1 spelling "pkg/Type"
        return f"{parts[0]}/msg/{parts[1]}"
    return msgtype


def _source(path: Path, ros: int, reader: Any) -> BagSource:
    connections: dict[str, list[Any]] = {}
    topics: dict[str, str] = {}
    for connection in reader.connections:
        connections.setdefault(connection.topic, []).append(connection)
        msgtype = _normalise(connection.msgtype)
        if topics.setdefault(connection.topic, msgtype) != msgtype:
            raise FormatError(
                path, f"topic {connection.topic} carries two message types, {topics[connection.topic]} and {msgtype}"
            )
    return BagSource(path, ros, topics, reader, connections)
