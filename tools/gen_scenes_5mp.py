#!/usr/bin/python3
"""Recorded-scene sets from a 5 MP camera: ../shared/tools/gen_scenes.py (POV-Ray) with a
2592 x 2048 camera (2.2 um pixels behind a 5 mm lens: f 2250 px, principal point off centre,
barrel distortion with tangential terms, the wide rig's 100 mm baseline) in place of its wide
camera. Same options as gen_scenes.py; `--camera` is set here. About 5 minutes a scene on one
core. The set's info records the camera as "5mp-2592x2048".

Usage: gen_scenes_5mp.py OUTDIR [--per-row N] [--seed S] [--kind K] [--hard]
       (STEREOHASH_GEN_SCENES=path/to/gen_scenes.py if it is not in ../shared/tools)
"""
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
GENERATOR = os.environ.get('STEREOHASH_GEN_SCENES',
                           os.path.join(HERE, '..', '..', 'shared', 'tools', 'gen_scenes.py'))
sys.path.insert(0, os.path.dirname(os.path.abspath(GENERATOR)))
import numpy as np  # noqa: E402
import gen_scenes as g  # noqa: E402

CAMERA_NAME = '5mp-2592x2048'


def use_5mp_camera():
    g.W, g.H, g.F_PX = 2592, 2048, 2250.0
    g.K = np.array([[g.F_PX, 0, 1290.6], [0, g.F_PX * 1.001, 1031.3], [0, 0, 1]])
    g.D = np.array([-0.12, 0.04, 0.0004, -0.0003, 0.0])
    g.RW, g.RH = 3300, 2600  # pinhole canvas covering the distorted view
    g.CAMS['left'] = np.array([-50.0, -300.0, 300.0])
    g.CAMS['right'] = np.array([50.0, -300.0, 300.0])


def main():
    if '--camera' in sys.argv:
        sys.exit('gen_scenes_5mp.py: the camera is this script\'s; drop --camera')
    g.use_wide_camera = use_5mp_camera
    sys.argv += ['--camera', 'wide']
    g.main()
    out = os.path.abspath(sys.argv[1])
    for name in os.listdir(out):  # the set's info names the camera it was rendered with
        path = os.path.join(out, name)
        if not name.endswith('.json') or name == 'index.json':
            continue
        with open(path) as f:
            info = json.load(f)
        if isinstance(info, dict) and info.get('camera') == 'wide':
            info['camera'] = CAMERA_NAME
            with open(path, 'w') as f:
                json.dump(info, f, indent=1)


if __name__ == '__main__':
    main()
