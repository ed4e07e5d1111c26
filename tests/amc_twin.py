"""A slow, obvious AMC reader in pure Python: the twin of the C scanner."""

import re


def parse_amc(data: bytes, skeleton):
    """(values as a list of rows, first frame number) by float() on every token."""
    columns, offset = {}, 0
    for joint in skeleton.joint_names:
        columns[joint] = offset
        offset += len(skeleton.dofs(joint))
    rows, first, row = [], None, None
    for raw in re.split(rb"\r\n|\r|\n", data):
        words = raw.decode("latin-1").split()
        if not words or words[0].startswith(("#", ":")):
            continue
        if len(words) == 1 and words[0].isdigit():
            first = int(words[0]) if first is None else first
            row = [float("nan")] * offset
            rows.append(row)
            continue
        start = columns[words[0]]
        for i, token in enumerate(words[1:]):
            row[start + i] = float(token)
    return rows, first
