"""What the take check finds: one :class:`Finding` per problem, in physical units and the
file's own joint names and frame numbers, and the kinds it knows."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

SEVERITIES = ("low", "medium", "high")
"""From a note worth knowing to a problem that spoils the take."""
_RANKS = {severity: rank for rank, severity in enumerate(SEVERITIES)}

KINDS = {
    "spike": "a joint's rotation or position far outside its neighbours for a few frames",
    "flip": "Euler angles that jump to an equivalent triple or by a whole turn: a jump that is not motion",
    "jump": "a joint's rotation jumps and stays: a change no joint makes in one frame",
    "gap": "missing values (NaN, or infinite) in a joint's channels",
    "frozen": "a channel held at one value while it moves before and after",
    "dead": "a channel that never moves while the joint's other channels do",
    "repeated": "frames equal to the frame before in every channel (dropped and filled by repetition)",
    "dropped": "frames missing between two: the body moves as far in one step as in two or more",
    "teleport": "the root jumps farther in a frame than anyone runs",
    "speed": "the root moves faster than anyone runs, for a while",
    "jitter": "high-frequency noise on a joint's channels",
    "bone": "the length of a bone with position channels drifts",
    "unit": "a height no person has in the length unit in effect",
    "up": "the character does not stand along y, the up axis readers take (upside down, along x, z-up)",
    "rate": "a Frame Time that disagrees with the motion's own rhythm (the speed a steady walk's strides make)",
    "skate": "a planted foot slides along the floor",
    "penetration": "a foot goes into the floor",
    "floor": "the feet rest on a floor away from level zero",
    "knee": "a knee bent backwards past what knees do",
    "elbow": "an elbow bent backwards past what elbows do",
    "header": "the file disagrees with its header: it breaks off before the frames it says it holds (a frame cut short), or goes on past them",
    "unreadable": "the file cannot be read as a take",
}
"""Every kind of finding, and what it means."""


@dataclass(frozen=True)
class Finding:
    """One problem of a take.  ``first`` and ``last`` are frame numbers as the file numbers them,
    ``joints`` the joints concerned as the file spells them, ``size`` how large it is in
    ``unit`` (deg, m, m/s, s, Hz, mm, % of the frames, or "" for a count); ``channel`` the worst channel
    ("joint dof") where there is one, ``detail`` a sentence for a person, and ``fix`` the steps
    that repair it, each (step name, options) as a recipe writes them (empty: none is known;
    ``("whole_frames", {})``, a file's whole frames read and written anew, is the recipe's
    ``whole_frames = true``)."""

    take: str
    kind: str
    joints: tuple[str, ...]
    first: int
    last: int
    severity: str
    size: float
    unit: str
    detail: str
    channel: str | None = None
    fix: tuple[tuple[str, dict[str, Any]], ...] = field(default=(), compare=False)

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"unknown kind of finding {self.kind!r}; one of {', '.join(KINDS)}")
        if self.severity not in _RANKS:
            raise ValueError(f"severity must be one of {SEVERITIES}, got {self.severity!r}")

    @property
    def rank(self) -> int:
        """0 for low .. 2 for high: the order a report sorts by."""
        return _RANKS[self.severity]

    def as_dict(self) -> dict[str, Any]:
        """The finding as JSON holds it: every field, ``joints`` a list, ``fix`` the step names."""
        d = asdict(self)
        d["joints"] = list(self.joints)
        d["fix"] = [name for name, _ in self.fix]
        return d
