"""The model: the step registry, the exceptions, length units, ``Skeleton`` and ``Motion``.

The bottom of the mocap floor: it imports nothing of the package but the file plumbing
(``motiontheater._io``).
"""
