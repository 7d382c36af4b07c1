#!/usr/bin/env python3
"""Draws the autorig evaluation set: characters of varied styles with reference joints.

Each character is drawn from a skeleton of named joints (canvas px, y down; "_l" is the
character's left, the right of the screen): limbs as capsules, heads and bodies as
(rotated) ellipses and polygons. The joints it was drawn from are its reference joints: where an
animator would put the rig's joints. Writes, per character, NAME.png (straight-alpha RGBA,
drawn at 3x and reduced, so edges are anti-aliased) and NAME.json:

    {"name", "kind": "humanoid"|"quadruped"|"prop", "budget": [min, max],
     "autorig_args": [...extra `sinew autorig` arguments...],
     "joints": {"pelvis": [x, y], ...}}

and index.json listing them. Usage: make_set.py OUT_DIR
"""
import json
import math
import random
import sys
from pathlib import Path

from PIL import Image, ImageDraw

SS = 3  # supersampling
BUDGET = {"humanoid": [12, 20], "quadruped": [15, 25], "prop": [1, 3]}
TEMPLATE = {"humanoid": ["--template", "humanoid"], "quadruped": ["--template", "quadruped"]}


class Canvas:
    def __init__(self, w, h, color):
        self.w, self.h = w, h
        self.img = Image.new("RGBA", (w * SS, h * SS), (0, 0, 0, 0))
        self.d = ImageDraw.Draw(self.img)
        self.color = color

    def s(self, p):
        return (p[0] * SS, p[1] * SS)

    def capsule(self, a, b, width, color=None):
        c = color or self.color
        r = width / 2
        self.d.line([self.s(a), self.s(b)], fill=c, width=int(round(width * SS)))
        for p in (a, b):
            self.circle(p, r, c)

    def chain(self, points, width, color=None):
        for a, b in zip(points, points[1:]):
            self.capsule(a, b, width, color)

    def taper(self, a, b, wa, wb, color=None):
        """A limb whose width goes from wa at a to wb at b (a convex quad with round ends)."""
        c = color or self.color
        dx, dy = b[0] - a[0], b[1] - a[1]
        n = math.hypot(dx, dy)
        nx, ny = -dy / n, dx / n
        quad = [
            (a[0] + nx * wa / 2, a[1] + ny * wa / 2),
            (b[0] + nx * wb / 2, b[1] + ny * wb / 2),
            (b[0] - nx * wb / 2, b[1] - ny * wb / 2),
            (a[0] - nx * wa / 2, a[1] - ny * wa / 2),
        ]
        self.poly(quad, c)
        self.circle(a, wa / 2, c)
        self.circle(b, wb / 2, c)

    def circle(self, p, r, color=None):
        x, y = p
        self.d.ellipse(
            [(x - r) * SS, (y - r) * SS, (x + r) * SS, (y + r) * SS], fill=color or self.color
        )

    def ellipse(self, p, rx, ry, angle_deg=0.0, color=None):
        t = math.radians(angle_deg)
        pts = []
        for k in range(64):
            a = 2 * math.pi * k / 64
            x, y = rx * math.cos(a), ry * math.sin(a)
            pts.append((p[0] + x * math.cos(t) - y * math.sin(t), p[1] + x * math.sin(t) + y * math.cos(t)))
        self.poly(pts, color)

    def poly(self, pts, color=None):
        self.d.polygon([self.s(p) for p in pts], fill=color or self.color)

    def noise(self, points, width, seed, r=3.0):
        """Small bumps along the sides of a polyline (a sketchy outline)."""
        rng = random.Random(seed)
        for a, b in zip(points, points[1:]):
            n = math.hypot(b[0] - a[0], b[1] - a[1])
            nx, ny = -(b[1] - a[1]) / n, (b[0] - a[0]) / n
            t = 4.0
            while t < n - 4:
                side = rng.choice([-1, 1])
                cx = a[0] + (b[0] - a[0]) * t / n + side * nx * width / 2
                cy = a[1] + (b[1] - a[1]) * t / n + side * ny * width / 2
                self.circle((cx, cy), r * (0.6 + 0.6 * rng.random()))
                t += 5 + 7 * rng.random()

    def image(self):
        return self.img.resize((self.w, self.h), Image.Resampling.BOX)


def mid(a, b, t=0.5):
    return (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t)


# ------------------------------------------------------------------------------ humanoids


def stick(j, width, head_r, c, feet=True):
    c.chain([j["pelvis"], j["chest"], j["neck"]], width)
    c.circle(j["head"], head_r)
    for s in "lr":
        c.chain([j["chest"], j["elbow_" + s], j["wrist_" + s]], width)
        c.chain([j["pelvis"], j["knee_" + s], j["ankle_" + s]], width)
        if feet:
            a = j["ankle_" + s]
            toe = (a[0] + (18 if s == "l" else -18), a[1] + 2)
            c.capsule(a, toe, width)


def stick_joints(dx=0, dy=0, arms="down", walk=0.0):
    j = {
        "pelvis": (256, 300),
        "chest": (256, 185),
        "neck": (256, 150),
        "head": (256, 118),
        "knee_l": (285 + 25 * walk, 385),
        "ankle_l": (300 + 40 * walk, 465),
        "knee_r": (227 - 10 * walk, 385),
        "ankle_r": (212 - 50 * walk, 465),
    }
    if arms == "down":
        j.update(elbow_l=(305, 240), wrist_l=(330, 300), elbow_r=(207, 240), wrist_r=(182, 300))
    elif arms == "up":  # juggling: forearms up
        j.update(elbow_l=(330, 215), wrist_l=(350, 150), elbow_r=(182, 215), wrist_r=(162, 150))
    else:  # out
        j.update(elbow_l=(325, 190), wrist_l=(395, 200), elbow_r=(187, 190), wrist_r=(117, 200))
    return {k: (x + dx, y + dy) for k, (x, y) in j.items()}


def ref_stick(j):
    keys = ["pelvis", "chest", "head"] + [f"{p}_{s}" for p in ("elbow", "wrist", "knee", "ankle") for s in "lr"]
    return {k: j[k] for k in keys}


def stick_man():
    c = Canvas(512, 512, (30, 30, 30, 255))
    j = stick_joints()
    stick(j, 9, 32, c)
    return c, ref_stick(j)


def stick_walker():
    c = Canvas(512, 512, (20, 60, 160, 255))
    j = stick_joints(arms="out", walk=1.0)
    stick(j, 12, 30, c)
    return c, ref_stick(j)


def stick_juggler():
    c = Canvas(512, 512, (120, 20, 20, 255))
    j = stick_joints(arms="up")
    stick(j, 8, 30, c)
    for p in [(150, 60), (256, 40), (362, 60)]:  # balls in the air: separate pieces
        c.circle(p, 16, (220, 160, 0, 255))
    return c, ref_stick(j)


def sketchy_stick():
    c = Canvas(512, 512, (60, 60, 60, 255))
    j = stick_joints(arms="out")
    stick(j, 12, 30, c)
    pts = [[j["pelvis"], j["chest"]]]
    for s in "lr":
        pts += [[j["chest"], j["elbow_" + s], j["wrist_" + s]], [j["pelvis"], j["knee_" + s], j["ankle_" + s]]]
    for k, p in enumerate(pts):
        c.noise(p, 12, seed=k, r=2.5)
    return c, ref_stick(j)


def cartoon(j, c, limb_w, torso, head_r, hand_r=0.0, foot=0.0, head_gap=False, detached=False):
    """A blobby cartoon: torso ellipse (rx, ry), thick tapered limbs, a round head."""
    rx, ry = torso
    tc = mid(j["pelvis"], j["chest"])
    if not detached:
        c.ellipse(tc, rx, ry)
        if not head_gap:
            c.capsule(j["chest"], j["neck"], limb_w * 0.9)
    else:
        c.ellipse(tc, rx, ry)
    c.circle(j["head"], head_r)
    for s in "lr":
        sh, hp = j["shoulder_" + s], j["hip_" + s]
        if detached:  # floating hands and feet only (Rayman-like)
            c.circle(j["wrist_" + s], hand_r)
            a = j["ankle_" + s]
            c.ellipse((a[0] + (8 if s == "l" else -8), a[1]), foot, foot * 0.55)
            continue
        c.taper(sh, j["elbow_" + s], limb_w, limb_w * 0.85)
        c.taper(j["elbow_" + s], j["wrist_" + s], limb_w * 0.85, limb_w * 0.7)
        c.taper(hp, j["knee_" + s], limb_w * 1.2, limb_w)
        c.taper(j["knee_" + s], j["ankle_" + s], limb_w, limb_w * 0.8)
        if hand_r:
            c.circle(j["wrist_" + s], hand_r)
        if foot:
            a = j["ankle_" + s]
            c.ellipse((a[0] + (foot * 0.6 if s == "l" else -foot * 0.6), a[1] + 3), foot, foot * 0.5)


def ref_cartoon(j, limbs=True):
    keys = ["pelvis", "chest", "head"]
    parts = ("shoulder", "elbow", "wrist", "hip", "knee", "ankle") if limbs else ("wrist", "ankle")
    keys += [f"{p}_{s}" for p in parts for s in "lr"]
    return {k: j[k] for k in keys}


def cartoon_joints(cx=256, top=60, scale=1.0, head=1.0, arms=0.0, legs_apart=1.0):
    def p(x, y):
        return (cx + x * scale, top + y * scale)

    j = {
        "head": p(0, 70 * head),
        "neck": p(0, 70 * head + 60 * head),
        "chest": p(0, 70 * head + 80 * head + 20),
        "pelvis": p(0, 70 * head + 80 * head + 130),
    }
    base = 70 * head + 80 * head
    j.update(
        shoulder_l=p(45, base + 28), shoulder_r=p(-45, base + 28),
        elbow_l=p(70 + 20 * arms, base + 85 - 30 * arms), elbow_r=p(-70 - 20 * arms, base + 85 - 30 * arms),
        wrist_l=p(85 + 50 * arms, base + 140 - 70 * arms), wrist_r=p(-85 - 50 * arms, base + 140 - 70 * arms),
        hip_l=p(25, base + 150), hip_r=p(-25, base + 150),
        knee_l=p(30 * legs_apart + 5, base + 215), knee_r=p(-30 * legs_apart - 5, base + 215),
        ankle_l=p(35 * legs_apart + 5, base + 275), ankle_r=p(-35 * legs_apart - 5, base + 275),
    )
    return j


def blob_kid():
    c = Canvas(512, 512, (240, 150, 60, 255))
    j = cartoon_joints(top=20, scale=1.0)
    cartoon(j, c, 30, (60, 85), 62, hand_r=17, foot=22)
    return c, ref_cartoon(j)


def chibi():
    c = Canvas(512, 512, (250, 120, 170, 255))
    j = cartoon_joints(top=10, scale=0.95, head=1.45, arms=0.3, legs_apart=0.8)
    cartoon(j, c, 28, (52, 75), 95, hand_r=16, foot=18)
    return c, ref_cartoon(j)


def muscle_man():
    c = Canvas(512, 512, (150, 90, 60, 255))
    j = cartoon_joints(top=30, scale=1.0, arms=0.6)
    j["shoulder_l"], j["shoulder_r"] = (j["shoulder_l"][0] + 25, j["shoulder_l"][1] - 8), (j["shoulder_r"][0] - 25, j["shoulder_r"][1] - 8)
    j["elbow_l"], j["elbow_r"] = (j["elbow_l"][0] + 30, j["elbow_l"][1]), (j["elbow_r"][0] - 30, j["elbow_r"][1])
    j["wrist_l"], j["wrist_r"] = (j["wrist_l"][0] + 25, j["wrist_l"][1] - 55), (j["wrist_r"][0] - 25, j["wrist_r"][1] - 55)
    cartoon(j, c, 40, (85, 90), 45, hand_r=22, foot=20)
    # V-shaped chest over the torso.
    ch = j["chest"]
    c.poly([(ch[0] - 95, ch[1] - 5), (ch[0] + 95, ch[1] - 5), (ch[0] + 35, ch[1] + 110), (ch[0] - 35, ch[1] + 110)])
    return c, ref_cartoon(j)


def floating_limbs():
    """A body with a detached head, hands and feet (Rayman-like): six pieces."""
    c = Canvas(512, 512, (90, 60, 200, 255))
    j = cartoon_joints(top=20, scale=1.0, arms=0.2)
    cartoon(j, c, 30, (55, 80), 60, hand_r=22, foot=26, head_gap=True, detached=True)
    return c, {k: j[k] for k in ["pelvis", "chest", "head", "wrist_l", "wrist_r", "ankle_l", "ankle_r"]}


def detached_head():
    c = Canvas(512, 512, (40, 140, 90, 255))
    j = cartoon_joints(top=20, scale=1.0)
    j["head"] = (j["head"][0], j["head"][1] - 12)
    cartoon(j, c, 28, (58, 82), 58, hand_r=15, foot=20, head_gap=True)
    return c, ref_cartoon(j)


def robot():
    c = Canvas(512, 512, (120, 130, 140, 255))
    j = cartoon_joints(top=40, scale=0.95, head=0.9)
    ch, pv = j["chest"], j["pelvis"]
    c.poly([(ch[0] - 60, ch[1] - 20), (ch[0] + 60, ch[1] - 20), (pv[0] + 50, pv[1] + 15), (pv[0] - 50, pv[1] + 15)])
    hd = j["head"]
    c.poly([(hd[0] - 45, hd[1] - 45), (hd[0] + 45, hd[1] - 45), (hd[0] + 45, hd[1] + 40), (hd[0] - 45, hd[1] + 40)])
    c.d.line([c.s(j["neck"]), c.s(ch)], fill=c.color, width=30 * SS)
    for s in "lr":
        for a, b in [("shoulder", "elbow"), ("elbow", "wrist"), ("hip", "knee"), ("knee", "ankle")]:
            c.d.line([c.s(j[f"{a}_{s}"]), c.s(j[f"{b}_{s}"])], fill=c.color, width=26 * SS)
            c.circle(j[f"{b}_{s}"], 17)
        a = j["ankle_" + s]
        dx = 22 if s == "l" else -22
        c.poly([(a[0] - 18 + dx / 2, a[1]), (a[0] + 18 + dx / 2, a[1]), (a[0] + 18 + dx / 2, a[1] + 16), (a[0] - 18 + dx / 2, a[1] + 16)])
    return c, ref_cartoon(j)


def dress_girl():
    c = Canvas(512, 512, (200, 60, 90, 255))
    j = cartoon_joints(top=30, scale=1.0, arms=0.1, legs_apart=0.7)
    cartoon(j, c, 24, (40, 70), 55, hand_r=13, foot=17)
    ch, pv = j["chest"], j["pelvis"]
    c.poly([(ch[0] - 35, ch[1] - 5), (ch[0] + 35, ch[1] - 5), (pv[0] + 90, pv[1] + 60), (pv[0] - 90, pv[1] + 60)])
    # Hair.
    hd = j["head"]
    c.ellipse((hd[0], hd[1] + 20), 70, 60)
    return c, ref_cartoon(j)


def tall_thin():
    c = Canvas(512, 768, (30, 110, 130, 255))
    j = cartoon_joints(top=40, scale=1.7, head=0.8, legs_apart=0.6)
    cartoon(j, c, 30, (80, 160), 60, hand_r=18, foot=26)
    return c, ref_cartoon(j)


def skeleton_bones():
    """A skeleton of separate bones: every bone its own piece."""
    c = Canvas(512, 512, (235, 230, 215, 255))
    j = stick_joints()
    gap = 7

    def bone(a, b, w):
        n = math.hypot(b[0] - a[0], b[1] - a[1])
        t = gap / n
        aa, bb = mid(a, b, t), mid(a, b, 1 - t)
        c.capsule(aa, bb, w)
        c.circle(aa, w * 0.85)
        c.circle(bb, w * 0.85)

    c.circle(j["head"], 30)  # skull
    c.ellipse(mid(j["chest"], j["pelvis"], 0.3), 38, 45)  # ribcage
    c.ellipse(j["pelvis"], 34, 18)  # pelvis
    c.capsule((256, 150), (256, 140), 10)  # neck vertebra
    for s in "lr":
        sx = 30 if s == "l" else -30
        sh = (256 + sx, 190)
        bone(sh, j["elbow_" + s], 10)
        bone(j["elbow_" + s], j["wrist_" + s], 9)
        bone((256 + sx * 0.7, 312), j["knee_" + s], 12)
        bone(j["knee_" + s], j["ankle_" + s], 11)
    ref = ref_stick(j)
    ref["chest"] = mid(j["chest"], j["pelvis"], 0.3)
    return c, ref


# ------------------------------------------------------------------------------ quadrupeds


def quad(c, j, body_w, leg_w, neck_w, head, tail_w, tail_pts):
    c.capsule(j["chest"], j["pelvis"], body_w)
    c.taper(j["chest"], j["neck"], neck_w * 1.3, neck_w)
    c.ellipse(j["head"], *head)
    c.chain([j["pelvis"]] + tail_pts, tail_w)
    for leg in ("front_l", "front_r", "back_l", "back_r"):
        c.taper(j["shoulder_" + leg], j["knee_" + leg], leg_w * 1.3, leg_w)
        c.taper(j["knee_" + leg], j["foot_" + leg], leg_w, leg_w * 0.8)


def quad_joints(chest, pelvis, neck, head, leg_len, knee_bend=6, spread=46, tail_end=None):
    j = {"chest": chest, "pelvis": pelvis, "neck": neck, "head": head}
    for leg, root in (("front", chest), ("back", pelvis)):
        for s, dx in (("l", spread / 2), ("r", -spread / 2)):
            sh = (root[0] + dx, root[1] + 10)
            kb = knee_bend if leg == "front" else -knee_bend
            j["shoulder_" + leg + "_" + s] = sh
            j["knee_" + leg + "_" + s] = (sh[0] + kb, sh[1] + leg_len * 0.5)
            j["foot_" + leg + "_" + s] = (sh[0], sh[1] + leg_len)
    if tail_end:
        j["tail"] = tail_end
    return j


def ref_quad(j):
    keys = ["chest", "pelvis", "neck", "head"]
    for leg in ("front", "back"):
        for s in "lr":
            keys += [f"knee_{leg}_{s}", f"foot_{leg}_{s}"]
    if "tail" in j:
        keys.append("tail")
    return {k: j[k] for k in keys}


def dog():
    c = Canvas(512, 512, (160, 110, 60, 255))
    j = quad_joints((340, 250), (170, 255), (385, 195), (420, 160), 170, tail_end=(80, 190))
    quad(c, j, 80, 26, 40, (45, 30, 15), 16, [(120, 230), (80, 190)])
    c.ellipse((400, 130), 10, 22, 20)  # ear
    return c, ref_quad(j)


def cat():
    c = Canvas(512, 512, (70, 70, 80, 255))
    j = quad_joints((330, 290), (180, 295), (365, 245), (390, 210), 150, tail_end=(95, 120))
    quad(c, j, 66, 20, 34, (38, 32, 0), 12, [(120, 270), (90, 200), (95, 120)])
    for ex in (375, 405):
        c.poly([(ex - 12, 190), (ex + 12, 190), (ex, 165)])
    return c, ref_quad(j)


def giraffe():
    c = Canvas(512, 768, (220, 170, 60, 255))
    j = quad_joints((330, 420), (190, 440), (400, 150), (425, 120), 270, knee_bend=4, tail_end=(120, 520))
    quad(c, j, 90, 20, 32, (38, 20, 25), 9, [(140, 470), (120, 520)])
    return c, ref_quad(j)


def horse():
    c = Canvas(512, 512, (110, 70, 40, 255))
    j = quad_joints((345, 230), (165, 240), (390, 150), (430, 120), 200, knee_bend=8, tail_end=(85, 300))
    quad(c, j, 95, 24, 44, (48, 22, 30), 18, [(110, 250), (85, 300)])
    return c, ref_quad(j)


def pig():
    c = Canvas(512, 512, (240, 170, 180, 255))
    j = quad_joints((320, 260), (190, 265), (360, 240), (395, 235), 110, knee_bend=3, spread=50, tail_end=(115, 235))
    quad(c, j, 120, 30, 70, (45, 40, 0), 8, [(130, 250), (115, 235)])
    return c, ref_quad(j)


def dragon():
    c = Canvas(640, 512, (40, 150, 70, 255))
    j = quad_joints((400, 300), (240, 310), (460, 190), (500, 150), 140, tail_end=(50, 230))
    quad(c, j, 80, 24, 30, (45, 25, 20), 22, [(150, 330), (90, 300), (50, 230)])
    # Wings from the shoulders.
    c.poly([(380, 270), (300, 90), (350, 120), (390, 60), (420, 140), (420, 270)])
    c.capsule((50, 230), (35, 200), 10)
    return c, ref_quad(j)


# ------------------------------------------------------------------------------ props


def sword():
    c = Canvas(512, 512, (180, 190, 200, 255))
    c.poly([(250, 80), (262, 80), (266, 340), (246, 340)])
    c.poly([(256, 60), (250, 80), (262, 80)])
    c.capsule((206, 345), (306, 345), 16, (150, 110, 40, 255))
    c.capsule((256, 350), (256, 420), 14, (90, 60, 30, 255))
    c.circle((256, 428), 12, (150, 110, 40, 255))
    return c, {"tip": (256, 66), "pommel": (256, 428)}


def bottle():
    c = Canvas(512, 512, (60, 160, 90, 200))
    c.ellipse((256, 320), 80, 120)
    c.capsule((256, 210), (256, 110), 40)
    c.capsule((256, 110), (256, 95), 50)
    return c, {"base": (256, 420), "shoulder": (256, 215), "mouth": (256, 100)}


def flag():
    c = Canvas(512, 512, (120, 80, 40, 255))
    c.capsule((180, 460), (180, 80), 12)
    c.poly([(180, 85), (380, 120), (330, 160), (380, 200), (180, 230)], (200, 30, 30, 255))
    return c, {"foot": (180, 455), "top": (180, 85), "flag_tip": (370, 160)}


def hammer():
    c = Canvas(512, 512, (110, 80, 50, 255))
    c.capsule((180, 420), (330, 150), 20)
    c.ellipse((345, 125), 75, 30, -60, (90, 90, 100, 255))
    return c, {"grip": (185, 412), "head": (340, 133)}


CHARACTERS = {
    "stick_man": ("humanoid", stick_man),
    "stick_walker": ("humanoid", stick_walker),
    "stick_juggler": ("humanoid", stick_juggler),
    "sketchy_stick": ("humanoid", sketchy_stick),
    "blob_kid": ("humanoid", blob_kid),
    "chibi": ("humanoid", chibi),
    "muscle_man": ("humanoid", muscle_man),
    "floating_limbs": ("humanoid", floating_limbs),
    "detached_head": ("humanoid", detached_head),
    "robot": ("humanoid", robot),
    "dress_girl": ("humanoid", dress_girl),
    "tall_thin": ("humanoid", tall_thin),
    "skeleton_bones": ("humanoid", skeleton_bones),
    "dog": ("quadruped", dog),
    "cat": ("quadruped", cat),
    "giraffe": ("quadruped", giraffe),
    "horse": ("quadruped", horse),
    "pig": ("quadruped", pig),
    "dragon": ("quadruped", dragon),
    "sword": ("prop", sword),
    "bottle": ("prop", bottle),
    "flag": ("prop", flag),
    "hammer": ("prop", hammer),
}


def main():
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    index = []
    for name, (kind, draw) in CHARACTERS.items():
        canvas, joints = draw()
        canvas.image().save(out / f"{name}.png", optimize=True)
        meta = {
            "name": name,
            "kind": kind,
            "budget": BUDGET[kind],
            "autorig_args": TEMPLATE.get(kind, []),
            "joints": {k: [round(v[0], 2), round(v[1], 2)] for k, v in joints.items()},
        }
        (out / f"{name}.json").write_text(json.dumps(meta, indent=1) + "\n")
        index.append(name)
    (out / "index.json").write_text(json.dumps(index, indent=1) + "\n")
    print(f"{len(index)} characters in {out}")


if __name__ == "__main__":
    main()
