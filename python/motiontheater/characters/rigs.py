"""Rigs: which joint of a skeleton turns which part of the body, and joint maps between two skeletons.

The alias tables are data, ``rigs.toml`` beside this module: for each known
rig (CMU/HDM05 ASF names, the CMU BVH conversion, HumanIK names as Mixamo and
most BVH exporters write them, the early Biovision names), the joint that
turns each part of the body (``left_thigh``: ASF bone ``lfemur``, BVH joint
``LeftUpLeg``).  :func:`recognise` finds the rig whose names a skeleton
has most of; :func:`joint_map` pairs the joints of two skeletons that turn
the same part.  Names are compared without case, separators (space, ``_``,
``-``, ``.``) or a namespace (``mixamorig:``).

Chains (``spine``, ``neck``) are matched end to end: the lowest joints
together, the highest together, and the joints between by their place along
the chain; a chain longer on the target side leaves its extra joints
unmapped (they keep their rest rotation).

A user's map file is TOML::

    # source joint = target joint
    [joints]
    lfemur = "LeftUpLeg"
    lwrist = ""            # an empty name: leave this source joint unmapped

Its pairs replace what the tables would pair for the joints it names, and
the tables pair the rest; ``aliases = false`` at the top uses its pairs
alone.  The root is named "root" or by its own name.
"""

from __future__ import annotations

import difflib
import functools
import os
import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from .._io import read_source
from ..model.errors import DuplicateError, UnknownNameError
from ..model.skeleton import ROTATIONS, Skeleton

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

TABLES = Path(__file__).with_name("rigs.toml")
CHAINS = ("spine", "neck")
"""Parts that are chains of joints, listed from the hips upwards."""
_SIDED = (
    "pelvis",
    "thigh",
    "shin",
    "foot",
    "toes",
    "clavicle",
    "upper_arm",
    "forearm",
    "wrist",
    "hand",
    "fingers",
    "thumb",
)
PARTS = ("hips", *CHAINS, "head", *(f"{side}_{part}" for side in ("left", "right") for part in _SIDED))
"""Every part a rig table may name, in the order maps are listed."""
_RIG_KEYS = ("title", "signature")


@dataclass(frozen=True)
class Rig:
    """A rig of the alias tables: its key, what it is, the names of the joints turning each part
    (chains in order; alternatives otherwise) and its signature names (see ``rigs.toml``)."""

    key: str
    title: str
    parts: tuple[tuple[str, tuple[str, ...]], ...]
    signature: tuple[str, ...] = ()


@functools.lru_cache(maxsize=8192)  # the same few hundred names, over every take of a database
def normal(name: str) -> str:
    """A joint name as the tables compare it: no namespace, case or separators
    ('mixamorig:Left_Up-Leg' -> 'leftupleg')."""
    return re.sub(r"[\s_.\-]", "", name.rsplit(":", 1)[-1]).lower()


@functools.cache
def rigs() -> tuple[Rig, ...]:
    """The rigs of ``rigs.toml``, in the file's order (earlier ones win ties)."""
    with open(TABLES, "rb") as f:
        data = tomllib.load(f)
    found = []
    for key, table in data.items():
        unknown = sorted(set(table) - set(PARTS) - set(_RIG_KEYS))
        if unknown:
            raise ValueError(f"{TABLES}: rig [{key}] names unknown parts {unknown}; the parts are {PARTS}")
        parts = tuple(
            (part, (table[part],) if isinstance(table[part], str) else tuple(table[part]))
            for part in PARTS
            if part in table
        )
        found.append(Rig(key, table.get("title", key), parts, tuple(table.get("signature", ()))))
    return tuple(found)


def joints_by_name(skeleton: Skeleton) -> dict[str, str]:
    """The joints that turn something (the root and every bone but end sites), by their
    :func:`normal` name: normal name -> the name as :attr:`Skeleton.point_names` gives it."""
    found: dict[str, str] = {}
    for name in skeleton.point_names:
        if name == skeleton.root.name or not skeleton.bone(name).end_site:
            found.setdefault(normal(name), name)
    found.setdefault("root", skeleton.root.name)
    return found


@dataclass(frozen=True)
class Recognised:
    """A skeleton's rig and, for each part it has, its joints (point names; chains in order)."""

    rig: Rig | None
    parts: dict[str, tuple[str, ...]]

    @property
    def title(self) -> str:
        """The rig's title, or "no known rig"."""
        return self.rig.title if self.rig else "no known rig"

    def part_of(self) -> dict[str, str]:
        """Each joint's part (chain members as "spine 2 of 3")."""
        named: dict[str, str] = {}
        for part, joints in self.parts.items():
            for i, joint in enumerate(joints):
                named[joint] = f"{part} {i + 1} of {len(joints)}" if part in CHAINS and len(joints) > 1 else part
        return named


def recognise(skeleton: Skeleton) -> Recognised:
    """The rig of the tables whose names the skeleton has most of (at least three, and one of its
    signature names where it has some), with the skeleton's joint for each part it has."""
    return skeleton.derived("rig", lambda: _recognise(skeleton))


def _recognise(skeleton: Skeleton) -> Recognised:
    present = joints_by_name(skeleton)
    best: Recognised = Recognised(None, {})
    best_score = 2
    for rig in rigs():
        if rig.signature and not any(normal(n) in present for n in rig.signature):
            continue
        parts: dict[str, tuple[str, ...]] = {}
        for part, names in rig.parts:
            found = [present[normal(n)] for n in names if normal(n) in present]
            if found:
                parts[part] = tuple(dict.fromkeys(found)) if part in CHAINS else (found[0],)
        score = sum(len(v) for v in parts.values())
        if score > best_score:
            best, best_score = Recognised(rig, parts), score
    return best


def wrist(skeleton: Skeleton, side: str) -> str | None:
    """The point at the ``side`` ("left", "right") wrist: the rig's wrist or hand joint, or where
    a BVH rig without hands ends its forearm, at its End Site (a BVH joint sits where it turns:
    the forearm's own point is the elbow).  None where the rig has neither."""
    parts = recognise(skeleton).parts
    found = parts.get(f"{side}_wrist") or parts.get(f"{side}_hand")
    if found:
        return found[0]
    forearm = parts.get(f"{side}_forearm")
    if skeleton.convention != "bvh" or not forearm:
        return None
    children = skeleton.children(forearm[-1])
    return children[0] if len(children) == 1 and skeleton.bone(children[0]).end_site else None


def match_chain(source: Sequence[str], target: Sequence[str]) -> list[tuple[str, str]]:
    """(source, target) pairs of two chains listed from the hips up: end to end, the joints between
    by their place along the chain; the longer chain's extra joints stay unpaired."""
    m, n = len(source), len(target)
    if not m or not n:
        return []
    if n <= m:
        return [(source[_spread(i, n, m)], target[i]) for i in range(n)]
    return [(source[k], target[_spread(k, m, n)]) for k in range(m)]


def _spread(i: int, count: int, over: int) -> int:
    """Index i of ``count`` evenly spread over ``over`` places, the ends kept."""
    return 0 if count == 1 else int(i * (over - 1) / (count - 1) + 0.5)


@dataclass(frozen=True)
class JointMap:
    """Which source joint each target joint follows.

    ``pairs``: (source joint, target joint) as :attr:`Skeleton.point_names`
    name them (the root by its own name), in target joint order; ``why`` the
    part (or "map file") of each pair; ``unmapped_source`` and
    ``unmapped_target``: the joints with rotation channels that no pair
    names.  ``source_rig`` and ``target_rig`` are the rigs recognised.
    """

    pairs: tuple[tuple[str, str], ...]
    why: tuple[str, ...]
    unmapped_source: tuple[str, ...]
    unmapped_target: tuple[str, ...]
    source_rig: Recognised
    target_rig: Recognised

    def describe(self, notes: dict[str, str] | None = None) -> str:
        """The map as text: one line per pair (with ``notes`` by target joint), then what is
        unmapped on each side."""
        notes = notes or {}
        width = max((len(s) for s, _ in self.pairs), default=0)
        t_width = max((len(t) for _, t in self.pairs), default=0)
        lines = [
            f"source rig: {self.source_rig.title}",
            f"target rig: {self.target_rig.title}",
            f"joint map ({len(self.pairs)} pairs, source -> target):",
        ]
        lines += [
            f"  {s:<{width}} -> {t:<{t_width}}  ({why}{'; ' + notes[t] if t in notes else ''})"
            for (s, t), why in zip(self.pairs, self.why)
        ]
        for side, names, effect in (
            ("source", self.unmapped_source, "their motion is not carried over"),
            ("target", self.unmapped_target, "they keep their rest rotation"),
        ):
            lines.append(
                f"unmapped {side} joints ({len(names)}): {', '.join(names)}; {effect}"
                if names
                else f"unmapped {side} joints: none"
            )
        return "\n".join(lines)


def read_map(path: str | os.PathLike) -> tuple[dict[str, str], bool]:
    """A map file's pairs {source: target} ("" for unmapped) and whether the alias tables fill in
    the rest; ValueError naming the file and what is wrong."""
    where = os.fspath(path)
    try:
        data = tomllib.loads(read_source(path)[0].decode("utf-8"))  # a FIFO or a device is refused
    except FileNotFoundError:
        raise FileNotFoundError(f"{where}: no such map file") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise ValueError(f"{where}: not valid TOML: {e}") from None
    unknown = sorted(set(data) - {"joints", "aliases"})
    if unknown:
        raise ValueError(
            f"{where}: unknown key(s) {', '.join(unknown)}; a map file has a [joints] table "
            '(source = "target") and optionally aliases = true/false'
        )
    aliases = data.get("aliases", True)
    if not isinstance(aliases, bool):
        raise ValueError(f"{where}: aliases must be true or false, got {aliases!r}")
    joints = data.get("joints", {})
    if not isinstance(joints, dict) or not all(isinstance(v, str) for v in joints.values()):
        raise ValueError(f'{where}: [joints] must hold source = "target" pairs of joint names')
    if not joints and not aliases:
        raise ValueError(f"{where}: no [joints] pairs, and aliases = false: nothing to map")
    return dict(joints), aliases


def _resolve(name: str, skeleton: Skeleton, side: str, where: str) -> str:
    """A joint name of a map file as the skeleton's point name; UnknownNameError with suggestions."""
    if skeleton.is_root(name):
        return skeleton.root.name
    if skeleton.has_joint(name) and not skeleton.bone(name).end_site:
        return name
    choices = [n for n in skeleton.point_names if n == skeleton.root.name or not skeleton.bone(n).end_site]
    close = difflib.get_close_matches(name, choices, n=3)
    hint = f"; did you mean {', '.join(repr(c) for c in close)}?" if close else f" (its joints: {', '.join(choices)})"
    label = skeleton.name or "(unnamed)"
    raise UnknownNameError(f"{where}: '{name}' is not a joint of the {side} skeleton '{label}'{hint}")


LIMBS = {
    f"{side} {limb}": tuple(f"{side}_{part}" for part in parts)
    for side in ("left", "right")
    for limb, parts in (("leg", ("thigh", "shin")), ("arm", ("upper_arm", "forearm")))
}
"""The limbs whose joints a retarget must drive: a figure with a leg or an arm left at rest is
no result (the tables' parts of each; a map file may leave one out on purpose)."""


def _require_limbs(target_rig: Recognised, chosen: dict[str, tuple[str, str]], source_rig: Recognised) -> None:
    """ValueError naming the target's limb joints that follow no source joint."""
    missing = []
    for limb, parts in LIMBS.items():
        joints = [target_rig.parts[p][0] if p in target_rig.parts else None for p in parts]
        if all(j is None for j in joints):
            missing.append(f"{limb} (no joint of it named as a known rig names it)")
        elif left := [j for j in joints if j is not None and j not in chosen]:
            missing.append(f"{limb} ({', '.join(left)})")
    if missing:
        raise ValueError(
            f"the target's {'; '.join(missing)} follow no joint of the source ({source_rig.title}): the "
            "character would move without them; give a map file (--map MAP.toml) with a [joints] table "
            'of source = "target" names for them'
        )


def joint_map(source: Skeleton, target: Skeleton, map_file: str | os.PathLike | None = None) -> JointMap:
    """The pairs of joints of ``source`` and ``target`` that turn the same part (see the module
    docstring), with the pairs of ``map_file`` replacing the tables' for the joints it names.

    Raises UnknownNameError for a map naming a joint that does not exist,
    DuplicateError for a target joint given two sources, and ValueError when
    no pair is found (no joints in common) or the target's root follows nothing.
    """
    source_rig, target_rig = recognise(source), recognise(target)
    given, aliases = read_map(map_file) if map_file is not None else ({}, True)
    where = os.fspath(map_file) if map_file is not None else ""
    chosen: dict[str, tuple[str, str]] = {}  # target -> (source, why)
    if aliases:
        for part in PARTS:
            pairs = match_chain(source_rig.parts.get(part, ()), target_rig.parts.get(part, ()))
            if part not in CHAINS:
                pairs = pairs[:1]
            for s, t in pairs:
                chosen[t] = (s, part)
        if not chosen and source.convention == target.convention:
            # two skeletons of no known rig: the joints of the same name turn the same part
            common = set(joints_by_name(source).values()) & set(joints_by_name(target).values())
            chosen = {t: (t, "same name") for t in common}
    explicit: dict[str, str] = {}
    for s_name, t_name in given.items():
        s = _resolve(s_name, source, "source", where)
        explicit[s] = _resolve(t_name, target, "target", where) if t_name else ""
    if explicit:
        taken = set(explicit) | {t for t in explicit.values() if t}
        chosen = {t: (s, why) for t, (s, why) in chosen.items() if s not in taken and t not in taken}
        seen: dict[str, str] = {}
        for s, t in explicit.items():
            if not t:
                continue
            if t in seen:
                raise DuplicateError(f"{where}: target joint '{t}' is given two sources, '{seen[t]}' and '{s}'")
            seen[t] = s
            chosen[t] = (s, "map file")
    if not chosen:
        raise ValueError(
            f"no joints in common: the source is {source_rig.title} ({_few(source)}), the target "
            f"{target_rig.title} ({_few(target)}); give a map file (--map MAP.toml) with a [joints] "
            'table of source = "target" names'
        )
    order = {name: i for i, name in enumerate(target.point_names)}
    ordered = sorted(chosen.items(), key=lambda item: order[item[0]])
    if target.root.name not in chosen:
        raise ValueError(
            f"the target's root '{target.root.name}' follows no source joint, so the character could "
            f"neither turn nor travel; map it in a map file ({_source_hips(source_rig, source)} = "
            f'"{target.root.name}")'
        )
    if map_file is None:
        _require_limbs(target_rig, chosen, source_rig)
    used = {s for s, _ in chosen.values()}
    return JointMap(
        pairs=tuple((s, t) for t, (s, _) in ordered),
        why=tuple(why for _, (_, why) in ordered),
        unmapped_source=tuple(n for n in _turning(source) if n not in used),
        unmapped_target=tuple(n for n in _turning(target) if n not in chosen),
        source_rig=source_rig,
        target_rig=target_rig,
    )


def _turning(skeleton: Skeleton) -> list[str]:
    """The joints with rotation channels, as point names."""
    return [n for n in skeleton.point_names if any(d in ROTATIONS for d in skeleton.dofs(n))]


def _few(skeleton: Skeleton) -> str:
    names = [n for n in skeleton.point_names if n == skeleton.root.name or not skeleton.bone(n).end_site]
    return ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")


def _source_hips(recognised: Recognised, skeleton: Skeleton) -> str:
    hips = recognised.parts.get("hips")
    return hips[0] if hips else skeleton.root.name
