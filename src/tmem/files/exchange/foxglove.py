"""A run as an MCAP file of Foxglove's published messages: the swarm in 3-D over time, and plots.

Every message is one of Foxglove's schemas (``foxglove.SceneUpdate``, ``foxglove.Vector2``), in
Protobuf as the ``foxglove-schemas-protobuf`` package defines them, so that Foxglove opens the file
with no extension.  One message per recorded time on each channel:

``/swarm`` (``foxglove.SceneUpdate``)
    One entity per recorded agent, its id the agent's name: a sphere for the agent (diameter
    ``R / 4``; posed at its position with its attitude, :mod:`tmem.files.exchange.attitude`; grey once
    removed) and a translucent sphere of radius ``R`` for its reach (two agents interact while
    theirs overlap).  The entity ``formation`` draws the tracked pairs as lines: solid while
    coupled (``F_en = 1``), faint otherwise.
``/metrics/rms_velocity`` (``foxglove.Vector2``)
    The point ``(t, RMS velocity)``: plot ``.y`` against time (or against ``.x``).
``/pairs/NAME_I-NAME_J/distance`` (``foxglove.Vector2``)
    Each tracked pair's point ``(t, |P_j - P_i|)``.

Log times are nanoseconds from the start of the run (Foxglove shows them as dates from
1970-01-01, the placeholder date of ``trajectory.nc``'s times).  Positions are metres in the run's
local frame, z up, in the frame ``world``; a run on fewer than three axes has 0 on the others.
The scenario and the frame are in the file's metadata record ``tmem``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tmem import __version__
from tmem.files.outputs import replace_file
from tmem.files.trajectory_file import FRAME
from tmem.files.exchange.recording import Recording

__all__ = ["EXPORT_MARK", "FRAME_ID", "TOPIC_RMS", "TOPIC_SCENE", "export_mcap", "pair_topic", "write_mcap"]

#: In the MCAP header (its ``library``): the mark of a file ``tmem export`` may replace.
EXPORT_MARK = "written by tmem export"
#: The frame every position is in.
FRAME_ID = "world"
TOPIC_SCENE = "/swarm"
TOPIC_RMS = "/metrics/rms_velocity"
#: An agent's sphere: its diameter as a share of ``R``.
BODY_SHARE = 0.25
#: Colours (r, g, b, a): a flying agent, a removed one, a reach, a coupled pair, an uncoupled one.
FLYING, REMOVED, REACH = (0.15, 0.35, 0.85, 1.0), (0.55, 0.55, 0.55, 1.0), (0.15, 0.35, 0.85, 0.08)
COUPLED, UNCOUPLED = (0.1, 0.1, 0.1, 1.0), (0.5, 0.5, 0.5, 0.35)


def pair_topic(name_i: str, name_j: str) -> str:
    """The channel of a pair's distance.

    Parameters
    ----------
    name_i, name_j : str
        The pair's agents' names.
    """
    return f"/pairs/{name_i}-{name_j}/distance"


def _sphere(entity, position: list[float], orientation: list[float], diameter: float, colour: tuple) -> None:
    """Add a sphere: ``position`` (m), ``orientation`` ``(qw, qx, qy, qz)``, ``colour`` ``(r, g, b, a)``."""
    sphere = entity.spheres.add()
    place, turn = sphere.pose.position, sphere.pose.orientation
    place.x, place.y, place.z = position
    turn.w, turn.x, turn.y, turn.z = orientation
    sphere.size.x = sphere.size.y = sphere.size.z = diameter
    sphere.color.r, sphere.color.g, sphere.color.b, sphere.color.a = colour


def _edges(entity, segments: list[tuple[list[float], list[float]]], colour: tuple) -> None:
    """Add the ``segments`` (pairs of points, m) as one list of lines, ``colour`` ``(r, g, b, a)``."""
    from foxglove_schemas_protobuf.LinePrimitive_pb2 import LinePrimitive

    if not segments:
        return
    line = entity.lines.add()
    line.type = LinePrimitive.LINE_LIST
    line.thickness = 2.0
    line.scale_invariant = True  # pixels, whatever the zoom
    line.pose.orientation.w = 1.0
    line.color.r, line.color.g, line.color.b, line.color.a = colour
    for ends in segments:
        for end in ends:
            point = line.points.add()
            point.x, point.y, point.z = end


def _scene(recording: Recording, f: int, quaternions: np.ndarray, columns: np.ndarray, stamp: int):
    """The ``foxglove.SceneUpdate`` of record ``f``: the agents, their reach, the formation."""
    from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate

    update = SceneUpdate()
    places, turns, flying = recording.positions[f].tolist(), quaternions[f].tolist(), recording.active[f].tolist()
    body, reach = BODY_SHARE * recording.radius, 2.0 * recording.radius
    for k, name in enumerate(recording.names):
        entity = update.entities.add()
        entity.timestamp.FromNanoseconds(stamp)
        entity.frame_id, entity.id = FRAME_ID, name
        _sphere(entity, places[k], turns[k], body, FLYING if flying[k] else REMOVED)
        if flying[k]:
            _sphere(entity, places[k], [1.0, 0.0, 0.0, 0.0], reach, REACH)
    if len(recording.pairs):
        entity = update.entities.add()
        entity.timestamp.FromNanoseconds(stamp)
        entity.frame_id, entity.id = FRAME_ID, "formation"
        drawn = [(i, j, flag) for (i, j), flag in zip(columns.tolist(), recording.flags[f].tolist()) if i >= 0 and j >= 0]
        _edges(entity, [(places[i], places[j]) for i, j, flag in drawn if flag == 1], COUPLED)
        _edges(entity, [(places[i], places[j]) for i, j, flag in drawn if flag != 1], UNCOUPLED)
    return update


def _point(t: float, value: float):
    from foxglove_schemas_protobuf.Vector2_pb2 import Vector2

    return Vector2(x=float(t), y=float(value))


def _pair_topics(recording: Recording) -> list[str]:
    """Each tracked pair's channel, in the pairs' order (an agent not recorded goes by its number)."""
    names = dict(zip(recording.agents.tolist(), recording.names))
    return [pair_topic(names.get(i, f"agent{i + 1}"), names.get(j, f"agent{j + 1}")) for i, j in recording.pairs.tolist()]


def _channels(writer, recording: Recording) -> dict[str, int]:
    """Register every channel with its Foxglove schema; return the channel ids by topic."""
    from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
    from foxglove_schemas_protobuf.Vector2_pb2 import Vector2
    from mcap_protobuf.schema import register_schema

    scene, point = register_schema(writer, SceneUpdate), register_schema(writer, Vector2)
    topics = {TOPIC_SCENE: scene, TOPIC_RMS: point, **{topic: point for topic in _pair_topics(recording)}}
    return {topic: writer.register_channel(topic, "protobuf", schema) for topic, schema in topics.items()}


def write_mcap(recording: Recording, path: Path) -> None:
    """Write the run to ``path`` as MCAP: the channels of the module text, one message per recorded time.

    Parameters
    ----------
    recording : Recording
        The run (:func:`tmem.files.exchange.recording.read_recording`).
    path : Path
        The file to write.
    """
    from mcap.writer import CompressionType, Writer

    quaternions = recording.attitude
    slot = {int(a): k for k, a in enumerate(recording.agents)}
    columns = np.array([[slot.get(int(a), -1) for a in pair] for pair in recording.pairs], dtype=np.int64).reshape(-1, 2)
    with path.open("wb") as f:
        writer = Writer(f, compression=CompressionType.ZSTD)
        writer.start(profile="", library=f"tmem {__version__} ({EXPORT_MARK})")
        writer.add_metadata("tmem", {"scenario": recording.scenario, "frame": FRAME, "frame_id": FRAME_ID})
        channels = _channels(writer, recording)
        pair_channels = [channels[topic] for topic in _pair_topics(recording)]
        stamps = np.round(recording.time * 1e9).astype(np.int64).tolist()
        for r, (t, stamp) in enumerate(zip(recording.time.tolist(), stamps)):
            messages = [(channels[TOPIC_SCENE], _scene(recording, r, quaternions, columns, stamp)),
                        (channels[TOPIC_RMS], _point(t, recording.rms_velocity[r]))]  # fmt: skip
            messages += [(c, _point(t, recording.distances[r, p])) for p, c in enumerate(pair_channels)]
            for channel, message in messages:
                writer.add_message(channel, log_time=stamp, data=message.SerializeToString(), publish_time=stamp)
        writer.finish()


def export_mcap(recording: Recording, out: Path, label: str = "--out ") -> Path:
    """Write the MCAP file ``out`` atomically (:func:`tmem.files.outputs.replace_file`); return it.

    Parameters
    ----------
    recording : Recording
        The run.
    out : Path
        The file: absent, or an earlier ``tmem export`` file, which is replaced.
    label : str
        Put before ``out`` in messages: ``"--out "`` when the user named it.
    """
    with replace_file(out, mark=EXPORT_MARK, label=label) as tmp:
        write_mcap(recording, tmp)
    return out
