"""The registration peers' error measure: per view, the RMS displacement of its points
placed by the estimated pose against the true pose, and the rotation error."""

import numpy as np


def point_errors(points, estimated, truth):
    """Per view RMS point displacement (m) and rotation error (degrees)."""
    rms, rot = [], []
    for p, e, t in zip(points, estimated, truth):
        h = np.c_[p, np.ones(len(p))]
        d = (h @ e.T)[:, :3] - (h @ t.T)[:, :3]
        rms.append(float(np.sqrt((d * d).sum(axis=1).mean())))
        r = np.linalg.inv(t)[:3, :3] @ e[:3, :3]
        rot.append(float(np.degrees(np.arccos(np.clip((np.trace(r) - 1) / 2, -1, 1)))))
    return rms, rot
