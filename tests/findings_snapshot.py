"""The check's findings on every real take, its variants and injected artifacts, saved and
compared: a refactor or a speed-up of the check that must not change what it finds is compared
against a snapshot taken before it (run from the checkout, the corpus as the tests find it).

    python tests/findings_snapshot.py save BEFORE.json     # before the change
    python tests/findings_snapshot.py compare BEFORE.json  # after it: the cases that differ
"""

import collections
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from artifacts import KINDS, inject
from motiontheater.databases.check import check_motion
from test_check import BVHS, TAKES, VARIANTS, _variant


def _shown(finding) -> str:
    """A finding as JSON, its fix steps with their options (as_dict keeps their names only)."""
    return json.dumps({**finding.as_dict(), "fix": repr(finding.fix)}, sort_keys=True)


def findings() -> dict[str, list[str]]:
    """Every case's findings: each take as found and in each variant, clean and with two of
    each kind of artifact put in (the same ones on every run: one seed per variant)."""
    out = {}
    with tempfile.TemporaryDirectory() as folder:
        for name in VARIANTS:
            rng = np.random.default_rng(26)
            for path in TAKES if name == "as found" else BVHS:
                take = _variant(path, name, Path(folder))
                out[f"{name} | {path.name} | clean"] = [_shown(f) for f in check_motion(take, str(path))]
                for kind in KINDS:
                    for trial in range(2):
                        made = inject(take, kind, rng)
                        if made is not None:
                            found = check_motion(made[0], str(path))
                            out[f"{name} | {path.name} | {kind} {trial}"] = [_shown(f) for f in found]
    return out


def main(command: str, snapshot: str) -> int:
    now = findings()
    if command == "save":
        Path(snapshot).write_text(json.dumps(now, indent=0))
        print(f"{len(now)} cases saved to {snapshot}")
        return 0
    before = json.loads(Path(snapshot).read_text())
    differ = [case for case in before if before[case] != now.get(case)]
    changed: collections.Counter = collections.Counter()  # every case's, in short: how many cases each
    for i, case in enumerate(differ):
        was, got = set(before[case]), set(now.get(case, []))
        if i < 15:
            print(case)
            print(
                "".join(f"  - {line}\n" for line in sorted(was - got))
                + "".join(f"  + {line}\n" for line in sorted(got - was))
            )
        for sign, lines in (("-", was - got), ("+", got - was)):
            for line in lines:
                f = json.loads(line)
                take = case.split(" | ")[1]
                changed[sign, take, f["kind"], ", ".join(f["joints"]), f["first"], f["last"], f["severity"]] += 1
    if len(differ) > 15:
        print("every change, in short (cases: -/+ take kind joints frames severity):")
        for (sign, take, kind, joints, first, last, severity), cases in sorted(
            changed.items(), key=lambda x: x[0][1:] + x[0][:1]
        ):
            print(f"  {cases:4d}: {sign} {take} {kind} {joints} {first}-{last} {severity}")
    print(f"{len(differ)} of {len(before)} cases differ")
    return 1 if differ else 0


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in ("save", "compare"):
        sys.exit(__doc__)
    sys.exit(main(*sys.argv[1:]))
