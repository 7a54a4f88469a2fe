"""The fuzzing entries of pkm's public API, driven by the mechanism registry (``tools/fuzz_report.py`` runs them).

:class:`Gen` makes random and adversarial inputs; :class:`Context` holds, per worker process, every
registered mechanism with its reference values and files; :data:`ENTRIES` lists one
:class:`Entry` per public entry point (loaders, generic core, each mechanism's closed forms,
indices, maps, dynamics), each a function ``(gen, adversarial) -> (callable, args, kwargs)``.
A mechanism added to the registry gets its build, closed-form and file entries without an edit here.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

import pkm
from pkm.mechanisms import module as mechanism_module
from pkm.mechanisms import names as mechanism_names
from pkm.papers.hexapod import pose_T_placement

NAN, INF = float("nan"), float("inf")
ADV_NUMBERS = (NAN, INF, -INF, 1e308, -1e308, 1e-308, 5e-324, 0.0, -0.0, 1e30, -1e30, 1e7, -1.0, -1e-3,
               10**400, -(10**400), np.float32(np.nan), np.int64(2**62))
ADV_OBJECTS = (None, "abc", "1.5", "", "nan", b"1", [], {}, (), object(), True, False, 1 + 2j, [[1.0, 2.0], [3.0]],
               {"a": 1}, np.array([]), np.array(["a", "b"]), np.array([1 + 1j]), set(), Ellipsis, slice(3),
               np.zeros((2, 2)), [None] * 3, ["1", "2", "3"], np.array([True, False, True]))


def finite(x, depth: int = 0) -> bool:
    """Every number in ``x`` finite (arrays, dataclasses, sequences, mappings walked)."""
    if depth > 8 or x is None or isinstance(x, (str, bytes, bool, int, np.bool_, np.integer, type)):
        return True
    if isinstance(x, (float, np.floating, complex, np.complexfloating)):
        return bool(np.isfinite(x))
    if isinstance(x, np.ma.MaskedArray):
        return finite(x.compressed(), depth + 1)
    if isinstance(x, np.ndarray):
        if x.dtype.kind in "fc":
            return bool(np.all(np.isfinite(x)))
        if x.dtype.kind == "O":
            return all(finite(v, depth + 1) for v in x.ravel()[:10000])
        return True
    pkm = ctx().pkm
    if isinstance(x, pkm.Mechanism):
        return finite(x.q_reference) and finite(dict(x.spec.parameters))
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return all(finite(getattr(x, f.name), depth + 1) for f in dataclasses.fields(x))
    if isinstance(x, dict):
        return all(finite(v, depth + 1) for v in x.values())
    if isinstance(x, (list, tuple)):
        return all(finite(v, depth + 1) for v in x[:10000])
    if hasattr(x, "translation") and hasattr(x, "rotation"):
        return finite(np.asarray(x.translation)) and finite(np.asarray(x.rotation))
    return True


# ---------------------------------------------------------------------- input generators
class Gen:
    """Random values, valid-looking or hostile, from one numpy generator."""

    def __init__(self, rng: np.random.Generator):
        self.rng = rng

    def pick(self, seq):
        return seq[int(self.rng.integers(len(seq)))]

    def chance(self, p: float) -> bool:
        return bool(self.rng.random() < p)

    def hostile(self):
        """Any hostile scalar or object."""
        return self.pick(ADV_NUMBERS + ADV_OBJECTS)

    def scale(self) -> float:
        return float(self.pick((1e-6, 1e-3, 1e-2, 0.05, 0.2, 1.0, 10.0)))

    def near(self, base, scale: float | None = None) -> np.ndarray:
        """``base`` plus Gaussian noise of a random scale (valid-looking to far off)."""
        base = np.asarray(base, dtype=float)
        return base + (self.scale() if scale is None else scale) * self.rng.standard_normal(base.shape)

    def corrupt(self, base):
        """A hostile variant of the array ``base``: a bad element, shape, type or magnitude."""
        base = np.asarray(base, dtype=float)
        r = int(self.rng.integers(12))
        flat = base.ravel().copy()
        if r == 0 and flat.size:
            out = flat.astype(object)
            out[int(self.rng.integers(flat.size))] = self.pick(ADV_NUMBERS)
            try:
                return np.asarray(out.tolist(), dtype=float).reshape(base.shape)
            except (OverflowError, ValueError, TypeError):
                return out.reshape(base.shape).tolist()
        if r == 1:
            return flat[:-1] if flat.size > 1 and self.chance(0.5) else np.append(flat, 0.1)
        if r == 2:
            return self.pick((flat.reshape(-1, 1), flat.reshape(1, -1), np.tile(flat, (2, 1)), flat.sum(),
                              np.stack([base, base]), flat[:0]))
        if r == 3:
            return self.hostile()
        if r == 4:
            return base * float(self.pick((1e6, 1e10, 1e100, 1e300, -1e300)))
        if r == 5:
            return base * float(self.pick((1e-10, 1e-100, 1e-300, 0.0)))
        if r == 6 and flat.size:
            out = flat.tolist()
            out[int(self.rng.integers(len(out)))] = self.pick(("x", None, [1.0], "1e3", True))
            return out
        if r == 7:
            return np.full(base.shape, self.pick((NAN, INF, -INF)))
        if r == 8:
            return self.pick((base.astype(np.float32), base.astype(np.int64), base.astype(complex), base.tolist(),
                              tuple(flat.tolist()), base.astype(object)))
        if r == 9:
            return base + 10.0 ** float(self.rng.uniform(0, 8)) * self.rng.standard_normal(base.shape)
        if r == 10:
            return {"value": base}
        return np.where(self.rng.random(base.shape) < 0.5, base, -base) * 1e3

    def value(self, base, adversarial: bool, scale: float | None = None):
        return self.corrupt(base) if adversarial else self.near(base, scale)

    def maybe(self, valid, adversarial: bool, p: float = 0.3):
        """``valid`` or, for adversarial inputs with probability ``p``, a hostile value."""
        return self.hostile() if adversarial and self.chance(p) else valid

    def text_mutation(self, text: str) -> str:
        """Cheap mutations of file text: truncations, deletions, duplications, swapped numbers and names."""
        rng = self.rng
        n = len(text)
        for _ in range(int(rng.integers(1, 4))):
            n = len(text)
            if n == 0:
                return text
            r = int(rng.integers(11))
            i = int(rng.integers(n))
            j = min(n, i + int(rng.integers(1, 200)))
            if r == 0:
                text = text[:i]
            elif r == 1:
                text = text[:i] + text[j:]
            elif r == 2:
                text = text[:j] + text[i:j] + text[j:]
            elif r in (3, 4, 5):  # a number replaced by a hostile one
                import re
                nums = [m.span() for m in re.finditer(r"-?\d+(\.\d+)?(e-?\d+)?", text)]
                if nums:
                    a, b = nums[int(rng.integers(len(nums)))]
                    text = text[:a] + self.pick(("nan", "inf", "-inf", "1e308", "-1e308", "1e-320", "-1", "0",
                                                 "1e9", "abc", "", "1 2", "0x10", "1_000", "--1", "+inf",
                                                 "\"3\"", "true", "[1]")) + text[b:]
            elif r == 6:
                text = text[:i] + self.pick(("<", ">", "&", "\"", "'", "\x00", "\ud800", "]]>", "<!--", "\n[x]\n",
                                             "= ", "[[closure]]\n", "<link/>", "</robot>", "\\", "&amp;",
                                             "\u202e", "ÿ")) + text[i:]
            elif r == 7:
                import re
                names = re.findall(r'"([A-Za-z_][A-Za-z0-9_]*)"', text)
                if len(names) >= 2:
                    a, b = self.pick(names), self.pick(names)
                    text = text.replace(f'"{a}"', f'"{b}"', int(rng.integers(1, 3)))
            elif r == 8:
                text = text[:i] + text[i:j].upper() + text[j:]
            elif r == 9:
                lines = text.split("\n")
                k = int(rng.integers(len(lines)))
                lines.insert(int(rng.integers(len(lines) + 1)), lines[k])
                text = "\n".join(lines)
            else:
                text = text[:i] + "".join(chr(int(c)) for c in rng.integers(32, 127, size=int(rng.integers(1, 9)))) \
                    + text[i:]
        return text


HOSTILE_XML = (
    ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">'
    '<!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;"><!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;">]>'
    '<robot name="&d;"><link name="base"/></robot>'),
    ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]><robot name="&x;">'
    '<link name="base"/></robot>'),
    '<?xml version="1.0"?><!DOCTYPE r SYSTEM "file:///etc/passwd"><robot name="r"><link name="base"/></robot>',
    ('<robot name="r" xmlns:xi="http://www.w3.org/2001/XInclude"><xi:include href="/etc/passwd" parse="text"/>'
    '<link name="base"/></robot>'),
    '<robot name="r"><link name="base"/>' + "<a>" * 300 + "</a>" * 300 + "</robot>",
    '<robot name="r">' + "".join(f'<link name="l{k}"/>' for k in range(10_050)) + "</robot>",
    ('<robot name="r"><link name="base"/><link name="a"><inertial><mass value="-1"/>'
    '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
    '<joint name="j" type="fixed"><parent link="base"/><child link="a"/></joint></robot>'),
    ('<robot name="r"><link name="base"/><link name="a"><inertial><mass value="1"/>'
    '<inertia ixx="nan" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
    '<joint name="j" type="fixed"><parent link="base"/><child link="a"/></joint></robot>'),
    ('<robot name="r"><link name="base"/><link name="a"><inertial><mass value="1"/>'
    '<inertia ixx="-5" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
    '<joint name="j" type="fixed"><parent link="base"/><child link="a"/></joint></robot>'),
    "", "<robot", "\x00\x01\x02", "<robot name='r'></robot>",
)


# ---------------------------------------------------------------------- per-worker context
class Context:
    """Mechanisms, reference values and files built once per worker process."""

    def __init__(self):
        import pkm
        from pkm.core.kinematics.task import TaskMap
        from pkm.data import dynamics_path
        from pkm.mechanisms import module

        self.pkm = pkm
        self.names = tuple(pkm.MECHANISMS)
        self.mech = {n: pkm.load(n) for n in self.names}
        self.mod = {n: module(n) for n in self.names}
        self.task = {n: TaskMap(m) for n, m in self.mech.items()}
        self.y_ref = {n: self.task[n].value(m.q_reference) for n, m in self.mech.items()}
        self.qa_ref = {n: m.actuated_q(m.q_reference) for n, m in self.mech.items()}
        self.urdf = {n: m.urdf for n, m in self.mech.items()}
        self.spec = {n: m.spec.to_toml() for n, m in self.mech.items()}
        self.motion_text = dynamics_path("prs3_motions.toml").read_text()
        self.tmp = Path(tempfile.mkdtemp(prefix="pkm_fuzz_"))
        self._lazy: dict[str, object] = {}
        # assembled configurations near the reference, by the closed forms
        rng = np.random.default_rng(0)
        self.assembled: dict[str, list[np.ndarray]] = {}
        for n, m in self.mech.items():
            qs = [m.q_reference.copy()]
            for _ in range(40):
                y = self.task[n].retract(self.y_ref[n], 0.02 * rng.standard_normal(self.task[n].size))
                try:
                    qs.append(self.mod[n].closed_form_configuration(m, y))
                except pkm.PkmError:
                    pass
            self.assembled[n] = qs

    def lazy(self, key: str, make: Callable[[], object]):
        if key not in self._lazy:
            self._lazy[key] = make()
        return self._lazy[key]


CTX: Context | None = None


def ctx() -> Context:
    global CTX
    if CTX is None:
        CTX = Context()
    return CTX


# ---------------------------------------------------------------------- entry points
@dataclasses.dataclass(frozen=True)
class Entry:
    """One public entry point: ``make(gen, adversarial) -> (function, args, kwargs)``.

    ``sentinel(result) -> bool`` says whether the non-finite values of a result are documented ones.
    """

    name: str
    make: Callable[[Gen, bool], tuple]
    sentinel: Callable[[object], bool] | None = None


ENTRIES: list[Entry] = []


def entry(name: str, sentinel=None):
    def deco(fn):
        ENTRIES.append(Entry(name, fn, sentinel))
        return fn
    return deco


def _mech(g: Gen, adversarial: bool, names=None):
    c = ctx()
    n = g.pick(tuple(names or c.names))
    if adversarial and g.chance(0.05):
        return n, g.pick((None, n, "delta", c.mech[n].model, 3))
    return n, c.mech[n]


def _q(g: Gen, n: str, adversarial: bool):
    """A configuration: assembled, perturbed (not assembled) or hostile."""
    c = ctx()
    q = g.pick(c.assembled[n])
    if adversarial:
        return g.corrupt(q)
    if g.chance(0.3):
        m = c.mech[n]
        import pinocchio as pin
        return pin.integrate(m.model, q, g.near(np.zeros(m.nv)))
    return q


def _solver_kwargs(g: Gen, adversarial: bool, names=("tol", "max_iter", "max_step")) -> dict:
    kw = {}
    if g.chance(0.3):
        k = g.pick(names)
        if adversarial:
            kw[k] = g.pick(ADV_NUMBERS + (None, "1", -5, 0, 10**9, 1.5))
        else:
            kw[k] = {"tol": 10.0 ** float(g.rng.uniform(-14, -4)), "max_iter": int(g.rng.integers(1, 40)),
                     "max_step": float(g.rng.uniform(0.01, 0.5)), "n_starts": int(g.rng.integers(1, 4)),
                     "rtol": 10.0 ** float(g.rng.uniform(-12, -3))}[k]
    return kw


# loaders ----------------------------------------------------------------
@entry("pkm.load")
def _load(g, adv):
    c = ctx()
    name = g.pick(c.names) if not adv else g.pick(("Delta", "delta ", "../delta", "/etc/passwd", "rrr3\x00",
                                                    "hexapod.urdf", "") + ADV_OBJECTS[:12])
    return c.pkm.load, (name,), {}


def _param_kwargs(g: Gen, n: str, adversarial: bool) -> dict:
    c = ctx()
    params = c.mod[n].Params()
    fields = [f.name for f in dataclasses.fields(params)]
    kw = {}
    for f in g.rng.choice(fields, size=int(g.rng.integers(1, min(4, len(fields)) + 1)), replace=False):
        v = getattr(params, str(f))
        if v is None:  # found for the design (the reference pose): stated only to corrupt it
            if adversarial:
                length = next(x.metadata["length"] for x in dataclasses.fields(params) if x.name == f)
                kw[str(f)] = g.corrupt(tuple(g.rng.normal(0.0, 0.1, length).tolist()))
            continue
        if isinstance(v, str):
            kw[str(f)] = v if not adversarial else g.pick(("", "x", None, 3, "P", "R", "literal", "sector"))
        elif isinstance(v, (tuple, list)):
            kw[str(f)] = tuple(g.near(v, 0.02 * g.scale()).tolist()) if not adversarial else g.corrupt(v)
        elif isinstance(v, (bool, int)):
            kw[str(f)] = int(g.rng.integers(0, 10)) if not adversarial else g.hostile()
        else:
            kw[str(f)] = float(v * (1.0 + 0.1 * g.scale() * g.rng.standard_normal())) if not adversarial else \
                g.pick(ADV_NUMBERS + ADV_OBJECTS[:14] + (-v, 0.0, v * 1e9, v * 1e-12))
    if adversarial and g.chance(0.1):
        kw["no_such_parameter"] = 1.0
    return kw


def _build_entry(n: str):
    @entry(f"pkm.build[{n}]")
    def _build(g, adv):
        return ctx().pkm.build, (n,), _param_kwargs(g, n, adv)
    return _build


for _n in mechanism_names():
    _build_entry(_n)


def _mutated_urdf(g: Gen, n: str, adversarial: bool) -> str:
    c = ctx()
    if adversarial and g.chance(0.3):
        return g.pick(HOSTILE_XML)
    return g.text_mutation(c.urdf[n]) if adversarial or g.chance(0.7) else c.urdf[n]


def _mutated_spec(g: Gen, n: str, adversarial: bool) -> str:
    c = ctx()
    if adversarial and g.chance(0.2):
        return g.pick(('format = "pkm.closures/2"\n', 'format = 1\n', "a = " + "[" * 2000 + "]" * 2000,
                       c.spec[n].replace('urdf = "', 'urdf = "../../etc/'),
                       c.spec[n].replace("format", "# format"), c.spec[n].replace("= [", "= \"[", 3),
                       c.spec[n] + "\n[reference]\nx = [1]\n", c.spec[n].replace("-1 }", "true }"),
                       c.spec[n].replace('default_branch = "', 'default_branch = ["') ,
                       c.spec[n].replace("[reference]", "[reference]\nbogus = [1e308]")))
    return g.text_mutation(c.spec[n]) if adversarial or g.chance(0.7) else c.spec[n]


@entry("pkm.from_strings")
def _from_strings(g, adv):
    c = ctx()
    n = g.pick(("rrr3", "delta", "prs3", "rrr3", "delta", "prs3", "hexapod"))
    urdf, spec = c.urdf[n], c.spec[n]
    which = int(g.rng.integers(3))
    if which in (0, 2):
        urdf = _mutated_urdf(g, n, adv)
    if which in (1, 2):
        spec = _mutated_spec(g, n, adv)
    if adv and g.chance(0.05):
        urdf, spec = g.pick(((None, spec), (urdf, None), (urdf.encode("utf-8", "surrogatepass"), spec), (urdf, 3),
                             ([urdf], spec)))
    return c.pkm.from_strings, (urdf, spec), {}


@entry("ClosureSpec.from_toml")
def _from_toml(g, adv):
    c = ctx()
    n = g.pick(c.names)
    text = _mutated_spec(g, n, adv)
    if adv and g.chance(0.05):
        text = g.hostile()
    return c.pkm.ClosureSpec.from_toml, (text,), {}


@entry("formats.spec_from_gepetto")
def _gepetto(g, adv):
    from pkm.core.formats import spec_from_gepetto
    text = (Path(__file__).resolve().parents[1] / "examples" / "gepetto_rssr" / "robot.yaml").read_text()
    text = g.text_mutation(text) if adv else text
    if adv and g.chance(0.05):
        text = g.hostile()
    joints = ["motor", "ball_b", "rocker_joint"]
    return spec_from_gepetto, (text, "robot.urdf", joints, "rssr"), {}


@entry("pkm.assemble")
def _assemble(g, adv):
    c = ctx()
    n, m = _mech(g, adv)
    kw: dict = {"restarts": int(g.rng.integers(0, 3)), "seed": int(g.rng.integers(0, 100)), "max_iter": 30}
    if adv and g.chance(0.5):
        kw[g.pick(("restarts", "seed", "max_iter", "tol"))] = g.hostile()
    return c.pkm.assemble, (m, _q(g, n, adv and g.chance(0.5))), kw


@entry("urdf.load_model")
def _load_model(g, adv):
    from pkm.core.model.urdf import load_model
    n = g.pick(("rrr3", "delta", "prs3", "hexapod"))
    text = _mutated_urdf(g, n, adv)
    if adv and g.chance(0.05):
        text = g.hostile()
    return load_model, (text,), {}


@entry("builder.from_files")
def _from_files(g, adv):
    c = ctx()
    n = g.pick(("rrr3", "delta", "prs3"))
    d = Path(tempfile.mkdtemp(dir=c.tmp))
    urdf, spec = _mutated_urdf(g, n, adv), _mutated_spec(g, n, adv)
    try:
        (d / f"{n}.urdf").write_text(urdf, encoding="utf-8", errors="surrogatepass")
        (d / f"{n}.closures.toml").write_text(spec, encoding="utf-8", errors="surrogatepass")
    except (UnicodeEncodeError, ValueError):
        pass
    path = d / f"{n}.closures.toml"
    if adv and g.chance(0.2):
        r = int(g.rng.integers(5))
        if r == 0:  # the URDF named through a symbolic link that leaves the folder
            os.symlink("/etc/hostname", d / "link.urdf")
            path.write_text(c.spec[n].replace(f'urdf = "{n}.urdf"', 'urdf = "link.urdf"'))
        elif r == 1:
            os.mkfifo(d / "fifo.urdf")
            path.write_text(c.spec[n].replace(f'urdf = "{n}.urdf"', 'urdf = "fifo.urdf"'))
        elif r == 2:
            path = g.pick(("/dev/zero", "/nonexistent/x.toml", str(d), "/etc/passwd", None, 3, "", b"x"))
        elif r == 3:
            os.mkfifo(d / "spec.toml")
            path = d / "spec.toml"
        else:
            path.write_text(c.spec[n].replace(f'urdf = "{n}.urdf"', f'urdf = "{d.name}/../{n}.urdf"'))
    from pkm.core.model.builder import from_files

    return from_files, (path,), {}


_EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
#: The acceptance set's files in the formats pkm reads: (folder, the file pkm.load takes, the files beside it).
_MODEL_FILES = (("mjcf_fourbar", "fourbar.xml", ()), ("sdf_slider_crank", "slider_crank.closures.toml",
                                                     ("slider_crank.sdf",)),
                ("gepetto_rssr", "robot.yaml", ("robot.urdf",)), ("ankle", "ankle.closures.toml", ("ankle.urdf",)),
                ("../tests/data/hyrodyn_fourbar", "submechanisms.yml", ("fourbar.urdf",)))


@entry("formats.read_mjcf")
def _read_mjcf(g, adv):
    from pkm.core.formats.mjcf import read_mjcf
    text = (_EXAMPLES / "mjcf_fourbar" / "fourbar.xml").read_text()
    text = g.text_mutation(text) if adv or g.chance(0.5) else text
    return read_mjcf, (g.hostile() if adv and g.chance(0.05) else text,), {}


@entry("formats.read_sdf")
def _read_sdf(g, adv):
    from pkm.core.formats.sdf import read_sdf
    text = (_EXAMPLES / "sdf_slider_crank" / "slider_crank.sdf").read_text()
    text = g.text_mutation(text) if adv or g.chance(0.5) else text
    return read_sdf, (g.hostile() if adv and g.chance(0.05) else text,), {}


@entry("formats.read_hyrodyn")
def _read_hyrodyn(g, adv):
    from pkm.core.formats.hyrodyn import read_hyrodyn
    folder = Path(__file__).resolve().parent / "data" / "hyrodyn_fourbar"
    text, urdf = (folder / "submechanisms.yml").read_text(), (folder / "fourbar.urdf").read_text()
    text = g.text_mutation(text) if adv or g.chance(0.5) else text
    return read_hyrodyn, (g.hostile() if adv and g.chance(0.05) else text, urdf, "fourbar.urdf", "fourbar"), {}


def _model_folder(g, adv) -> Path:
    """One of :data:`_MODEL_FILES` copied to a fresh folder, one of its files mutated; the path pkm.load takes."""
    folder, main, others = g.pick(_MODEL_FILES)
    d = Path(tempfile.mkdtemp(dir=ctx().tmp))
    files = (main, *others)
    victim = g.pick(files)
    for name in files:
        text = (_EXAMPLES / folder / name).read_text()
        if name == victim and (adv or g.chance(0.5)):
            text = g.text_mutation(text)
        try:
            (d / name).write_text(text, encoding="utf-8", errors="surrogatepass")
        except (UnicodeEncodeError, ValueError):
            pass
    return d / main


@entry("pkm.load(file)")
def _load_file(g, adv):
    path = _model_folder(g, adv)
    if adv and g.chance(0.1):
        path = path.with_suffix(g.pick((".xml", ".sdf", ".yaml", ".mjcf")))
    return ctx().pkm.load, (path,), {}


@entry("formats.spec_skeleton")
def _spec_skeleton(g, adv):
    from pkm.core.formats.imported import spec_skeleton
    path = _model_folder(g, adv)
    model = {".toml": ".sdf", ".yaml": ".urdf"}.get(path.suffix)
    return spec_skeleton, (path.with_name(path.name.split(".")[0] + model) if model else path,), {}


@entry("pkm.quantity")
def _quantity(g, adv):
    text = g.pick(("20mm", "5deg", "-3.5e-2 m", "0.81", "1g", "12 cm", "7 rad"))
    if adv:
        text = g.pick((g.hostile(), text[::-1], text + "x", "1e999mm", "--3mm", "mm", " ", "5 deg deg", "nanmm"))
    kind = g.pick((None, "length", "angle", "mass") + (("volume", 3, np.zeros(3)) if adv else ()))
    return ctx().pkm.quantity, (text, kind), {}


def _follow(g, adv, task: bool):
    c = ctx()
    n, m = _mech(g, adv)
    mm = c.mech[n]
    k = int(g.rng.integers(1, 4))
    if task:
        y0 = pkm.TaskMap.of(mm).value(mm.q_reference)
        samples = np.array([y0] * k)
        if not pkm.TaskMap.of(mm).pose:
            samples = samples + g.near(np.zeros_like(samples), 0.01)
    else:
        samples = np.array([mm.actuated_q(mm.q_reference)] * k) + g.near(np.zeros((k, mm.na)), 0.01)
    if adv:
        samples = g.corrupt(samples)
    kw: dict = {"efforts": g.chance(0.5)}
    if adv and g.chance(0.3):
        kw[g.pick(("q0", "tol", "wrench", "efforts"))] = g.hostile()
    fn = c.pkm.follow_task if task else c.pkm.follow_actuators
    return fn, (m, samples), kw


def _nan_at_jumps(traj) -> bool:
    """A trajectory's NaN rates and efforts are documented at the samples its jumps name (a singular map)."""
    bad = {k for arr in (traj.v, traj.a, traj.efforts) if arr is not None for k in np.flatnonzero(
        ~np.all(np.isfinite(arr), axis=1))}
    return bad <= {j.index for j in traj.jumps} and bool(np.all(np.isfinite(traj.q)))


@entry("pkm.follow_task", sentinel=_nan_at_jumps)
def _follow_task(g, adv):
    return _follow(g, adv, True)


@entry("pkm.follow_actuators", sentinel=_nan_at_jumps)
def _follow_actuators(g, adv):
    return _follow(g, adv, False)


#: The mechanisms the compiled kernels' entries (``Kernels.inverse_dynamics``, ``Kernels.close_loops_path``,
#: ``maps.task_map``) draw from: None, every registered one (the full run). A smoke run may name fewer
#: (tests/test_fuzz.py): each mechanism's kernels are a twin built and a C library compiled per kernel, 0.3 to 1.8 s of
#: CPU each (the hexapod's map), where the calls themselves take milliseconds.
KERNEL_MECHANISMS: tuple[str, ...] | None = None


def _kernels(n: str):
    c = ctx()
    return c.lazy(f"kernels:{n}", lambda: c.pkm.Kernels(c.mech[n]))


def _kernel_mechanism(g: Gen) -> str:
    """A mechanism for a compiled kernels' entry: one of :data:`KERNEL_MECHANISMS` (default every registered one)."""
    return g.pick(KERNEL_MECHANISMS or ctx().names)


@entry("Kernels.inverse_dynamics")
def _kernels_inverse_dynamics(g, adv):
    c = ctx()
    n = _kernel_mechanism(g)
    m = c.mech[n]
    batch = g.chance(0.3)
    q = np.array([_q(g, n, False) for _ in range(3)]) if batch else _q(g, n, False)
    qd = g.near(np.zeros((3, m.na) if batch else m.na), 1.0)
    qdd = g.near(np.zeros((3, m.na) if batch else m.na), 1.0)
    args = [q, qd, qdd]
    if adv:
        i = int(g.rng.integers(3))
        args[i] = g.corrupt(args[i]) if g.chance(0.7) else g.hostile()

    def run(*a):
        return _kernels(n).inverse_dynamics(*a)
    return run, tuple(args), {}


@entry("Kernels.at")
def _kernels_at(g, adv):
    """The 3-PRS's kernels with a coupler joint's origin and the platform's mass as design inputs, bound to a
    design near the file's (adversarial: corrupt or hostile values, unknown names), then one sample's efforts."""
    c = ctx()
    m = c.mech["prs3"]
    K = c.lazy("kernels:prs3:design", lambda: c.pkm.Kernels(m, design=("coupler_1_tip_fixed.z", "platform_link.m")))
    values: object = dict(zip(K.design.names, K.design.base * (1.0 + g.near(np.zeros(2), 0.05))))
    if adv:
        values = (g.pick(({"platform_link.m": g.hostile()}, {"nowhere.x": 0.1}, {"platform_link.m": -1.0},
                          g.corrupt(K.design.base), g.hostile())))
    q, qd, qdd = m.q_reference, g.near(np.zeros(m.na), 1.0), g.near(np.zeros(m.na), 1.0)

    def run(v):
        return K.at(v).inverse_dynamics(q, qd, qdd)
    return run, (values,), {}


@entry("Kernels.close_loops_path")
def _kernels_path(g, adv):
    c = ctx()
    n = _kernel_mechanism(g)
    k = int(g.rng.integers(1, 5))
    targets = np.array([c.qa_ref[n]] * k) + g.near(np.zeros((k, c.mech[n].na)), 0.005)
    kw: dict = {}
    if adv:
        targets = g.corrupt(targets)
        if g.chance(0.3):
            kw[g.pick(("q0", "tol", "max_iter"))] = g.hostile()

    def run(t, **kwargs):
        return _kernels(n).close_loops_path(t, **kwargs).q
    return run, (targets,), kw


@entry("maps.task_map")
def _task_map(g, adv):
    from pkm.core.analysis.maps import workspace_map

    c = ctx()
    n = _kernel_mechanism(g)
    task = c.task[n]
    names = [k for k in task.keys if k in task.value_names]
    y0 = task.named(c.mech[n].q_reference)
    axes = {k: y0[k] + np.linspace(-0.01, 0.01, int(g.rng.integers(1, 6))) for k in names[:2]}
    kw: dict = {"length": 0.1}
    if adv:
        key = g.pick(names[:2] or ["x"])
        axes[key] = g.corrupt(axes.get(key, np.zeros(2)))
        if g.chance(0.3):
            kw[g.pick(("length", "tol", "max_iter", "branch", "seed"))] = g.hostile()

    def run(a, **kwargs):
        m = workspace_map(c.mech[n], a, kernels=_kernels(n), **kwargs)
        return m.condition_index("2")[m.reachable], m.size
    return run, (axes,), kw


@entry("sweeps.space")
def _sweep_space(g, adv):
    from pkm import sweeps
    from pkm.sweeps.family import RegisteredFamily

    kind = g.pick(("grid", "sobol", "latin_hypercube", "table"))
    spec: object = g.pick(("5cm:20cm:3", "5cm:20cm", [0.05, 0.1], "10cm", (0.05, 0.2)))
    n: object = int(g.rng.integers(1, 20))
    if adv:
        what = g.pick(("spec", "n", "name"))
        if what == "spec":
            spec = g.pick((g.hostile(), "5cm:20deg:3", "5cm:20cm:-1", "20cm:5cm", "::", "5cm:20cm:3:4", [g.hostile()]))
        elif what == "n":
            n = g.hostile()
    name = g.pick(("h", "a", "R", "", "branch")) if adv and g.chance(0.3) else "h"

    def run(kind, spec, n):
        space = {"grid": lambda: sweeps.grid(**{name: spec}), "table": lambda: sweeps.table({name: spec}),
                 "sobol": lambda: sweeps.sobol(n, seed=1, **{name: spec}),
                 "latin_hypercube": lambda: sweeps.latin_hypercube(n, seed=1, **{name: spec})}[kind]()
        return space.designs(RegisteredFamily("rrr3").units).values
    return run, (kind, spec, n), {}


@entry("pkm.sweep")
def _sweep(g, adv):
    from pkm import sweeps

    n = g.pick(("rrr3", "delta"))
    param = {"rrr3": "h", "delta": "R"}[n]
    values: object = [float(v) for v in np.round(g.rng.uniform(0.05, 0.2, int(g.rng.integers(1, 4))), 4)]
    objectives: object = {"rrr3": ["gci:step=5cm", "cov=coverage:step=5cm"],
                          "delta": ["condition", "workspace_volume:spacing=3cm"]}[n]
    kw: dict = {"scheduler": "serial", "progress": False}
    if adv:
        what = g.pick(("values", "objective", "kw"))
        if what == "values":
            values = g.corrupt(np.asarray(values)) if g.chance(0.5) else [g.hostile()]
        elif what == "objective":
            objectives = [g.pick(("gci:step=", "gci:step=-1cm", "gci:step=1e-9", "condition:pose=x=", ":", "gci:route=x",
                                  "condition:pose=q=1", "condition:kind=7", "=gci", "design=gci", "nope.py:f",
                                  "peak_effort:motion=99", g.hostile()))]
        else:
            kw[g.pick(("chunk_size", "fixed", "out", "progress", "scheduler"))] = g.pick(ADV_OBJECTS + ADV_NUMBERS)

    def run(values, objectives, **k):
        res = c.pkm.sweep(n, sweeps.table({param: values}), objectives, **k)
        return [v[~np.isnan(v)] for v in (res.column(o)[res.ok] for o in res.objectives)]  # (NaN: a null)
    c = ctx()
    return run, (values, objectives), kw


_SWEEP_RESULTS: dict = {}


def _sweep_results() -> dict:
    """Two small sweeps' results, made once per process: one whose designs succeed, one whose every design fails."""
    if not _SWEEP_RESULTS:
        from pkm import sweeps

        for key, h in (("ok", [0.1, 0.15]), ("failed", [-0.1, -0.15])):
            _SWEEP_RESULTS[key] = ctx().pkm.sweep("rrr3", sweeps.table({"h": h}),
                                                  ["gci:step=5cm", "cov=coverage:step=5cm"], scheduler="serial")
    return _SWEEP_RESULTS


@entry("SweepResult")
def _sweep_result(g, adv):
    """What a sweep returns, asked for its best designs, fronts, columns, failures; and files read as results."""
    from pkm import sweeps
    from pkm.sweeps.results import pareto_front

    res = _sweep_results()["failed" if adv and g.chance(0.3) else "ok"]
    names = ["gci:step=5cm", "cov"]
    method = g.pick(("best", "pareto", "column", "failures", "check", "pareto_front", "read"))
    arg: object = {"best": g.pick(names), "pareto": names, "column": g.pick([*names, "h", "design"]),
                   "pareto_front": g.rng.uniform(0, 1, (int(g.rng.integers(0, 6)), 2)),
                   "read": ctx().tmp / "missing.parquet"}.get(method)
    n: object = int(g.rng.integers(1, 4))
    if adv:
        if g.chance(0.7):
            arg = g.pick((g.hostile(), "nope", "h", "status", "message", [g.hostile()], [*names, "nope"], [],
                          g.corrupt(np.ones((3, 2))), ctx().tmp))
        else:
            n = g.hostile()

    def run(method, arg, n):
        if method == "best":
            return res.best(arg, n)
        if method == "pareto":
            return res.pareto(arg)
        if method == "column":
            v = res.column(arg)
            return v[~np.isnan(v)]  # (NaN: a null)
        if method == "failures":
            return res.failures()
        if method == "check":
            return res.check().stats
        if method == "pareto_front":
            return pareto_front(arg)
        return sweeps.read(arg).stats
    return run, (method, arg, n), {}


@entry("pkm.reconfigure")
def _reconfigure(g, adv):
    c = ctx()
    m = c.mech["hexapod"]
    y = c.task["hexapod"].retract(c.y_ref["hexapod"], g.near(np.zeros(c.task["hexapod"].size), 0.01))
    limits = [(-0.5, 0.5)]
    kw: dict = {"length": 0.1, "grid": 7, "kernels": _kernels("hexapod")}  # (the twin, built once)
    if g.chance(0.3):
        kw["rate_limit"] = 0.05
    poses, params = [y, y], ["beta_1"]
    if adv:
        what = g.pick(("poses", "params", "limits", "kw"))
        if what == "poses":
            poses = [g.corrupt(y)]
        elif what == "params":
            params = g.pick((["alpha_1"], [], ["beta_1", "beta_1"], "beta_1", [None]))
        elif what == "limits":
            limits = g.pick(([(0.5, -0.5)], [(np.nan, 1.0)], [(-1e9, 1e9)], [], g.hostile()))
        else:
            kw[g.pick(("length", "index", "rate_limit", "grid", "tol", "branch", "kernels"))] = g.hostile()

    def run(*a, **k):
        return c.pkm.reconfigure(*a, **k).x
    return run, (m, poses, params, limits), kw


@entry("formats.mjcf_from_mechanism")
def _to_mjcf(g, adv):
    from pkm.core.formats.to_mjcf import mjcf_from_mechanism

    _, m = _mech(g, adv)
    return mjcf_from_mechanism, (m,), {}


@entry("motion.load_motions")
def _load_motions(g, adv):
    from pkm.motion import load_motions
    c = ctx()
    d = c.tmp / f"m{int(g.rng.integers(1 << 30))}.toml"
    text = g.text_mutation(c.motion_text) if adv or g.chance(0.7) else c.motion_text
    if adv and g.chance(0.2):
        text = g.pick((('format = "pkm.motion/1"\ncoordinates = ["z"]\n[case.a]\nduration = 1e6\ndt = 1e-300\n'
                       'z = { law = "constant", value = 1.0 }\n'),
                       ('format = "pkm.motion/1"\ncoordinates = ["z"]\n[case.a]\nduration = 1.0\ndt = 0.5\n'
                       'z = { law = "cosine", offset = 1e308, amplitude = 1e308, omega = 1e308 }\n'),
                       ('format = "pkm.motion/1"\ncoordinates = ["z"]\n[case.a]\nduration = 1.0\ndt = 0.5\n'
                       'z = { law = "linear", start = true, rate = 1 }\n'), "x = " + "[" * 3000))
    try:
        d.write_text(text, encoding="utf-8", errors="surrogatepass")
    except (UnicodeEncodeError, ValueError):
        d.write_text("")
    path = d if not (adv and g.chance(0.1)) else g.pick(("/dev/zero", None, 3, "prs3_motions.toml", "nope.toml"))

    def load_and_sample(p):
        return {k: m.sample() for k, m in load_motions(p).items()}
    return load_and_sample, (path,), {}


@entry("Motion.sample")
def _motion_sample(g, adv):
    from pkm.motion import load_motions
    c = ctx()
    motions = c.lazy("motions", lambda: load_motions("prs3_motions.toml"))
    m = g.pick(list(motions.values()))
    t = None if g.chance(0.2) else (g.near(np.linspace(0, m.duration, 5), 1.0) if not adv
                                     else g.corrupt(np.linspace(0, m.duration, 5)))
    return m.sample, (t,), {}


# generic core -----------------------------------------------------------
def _target(g: Gen, n: str, adversarial: bool):
    c = ctx()
    task = c.task[n]
    y = task.value(g.pick(c.assembled[n]))
    if adversarial:
        if g.chance(0.15):
            return g.pick(({"x": 0.0}, {k: 0.0 for k in task.names}, np.eye(4), np.ones((4, 4))))
        return g.corrupt(y)
    return task.retract(y, g.near(np.zeros(task.size), g.pick((1e-3, 1e-2, 0.05, 0.2, 1.0))))


#: The mechanisms whose every joint can be actuated (scalar joints only: no free-flyer, no ball joint).
ALL_ACTUATED = ("rrr3", "delta")


def _all_actuated(n: str):
    """Mechanism ``n`` with every joint actuated: no passive coordinate, the loop closure only a check that the
    actuated values close the loops (built once, from its files with the spec's ``actuated`` list replaced)."""
    c = ctx()

    def make():
        joints = ", ".join(f'"{j}"' for j in c.mech[n].joints)
        return c.pkm.from_strings(c.urdf[n], re.sub(r"(?m)^actuated = \[.*\]$", f"actuated = [{joints}]", c.spec[n]))

    return c.lazy(f"all actuated {n}", make)


#: A passive joint to actuate too: redundant actuation with passive joints left (the joint depends on the motors).
REDUNDANT = {"rrr3": "elbow_1", "delta": "knee_1"}


def _redundant(n: str):
    """Mechanism ``n`` with :data:`REDUNDANT`'s joint actuated too (built once, its warning that the joint depends on
    the others silenced): the loop closure follows the independent actuators, the dependent one released."""
    import warnings

    c = ctx()

    def make():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", c.pkm.errors.PkmWarning)
            return c.pkm.from_strings(c.urdf[n], dataclasses.replace(
                c.mech[n].spec, actuated=c.mech[n].actuated_names + (REDUNDANT[n],)))

    return c.lazy(f"redundant {n}", make)


@entry("pkm.solve_ik")
def _solve_ik(g, adv):
    n, m = _mech(g, adv)
    if adv and n in ALL_ACTUATED and g.chance(0.1):
        m = _all_actuated(n)
    kw = _solver_kwargs(g, adv)
    if g.chance(0.2):
        kw["q0"] = _q(g, n, adv)
    if g.chance(0.2):
        branches = list(ctx().mech[n].spec.branches)
        kw["branch"] = g.pick(branches) if not adv else g.pick(branches + ["nope", None, 3])
    return ctx().pkm.solve_ik, (m, _target(g, n, adv)), kw


@entry("pkm.close_loops")
def _close_loops(g, adv):
    n, m = _mech(g, adv)
    qa = ctx().qa_ref[n]
    kw = _solver_kwargs(g, adv)
    if g.chance(0.2):
        kw["q0"] = _q(g, n, adv)
    if adv and g.chance(0.1):
        kw["raise_on_failure"] = False
    if adv and n in ALL_ACTUATED and g.chance(0.1):  # (its own actuated values, closing the loops or near them)
        m = _all_actuated(n)
        qa = m.actuated_q(m.q_reference)
        return ctx().pkm.close_loops, (m, qa if g.chance(0.5) else g.near(qa, g.pick((1e-3, 1e-2)))), kw
    if n in REDUNDANT and g.chance(0.1):  # (the actuated values of a closed configuration, or near them: inconsistent)
        m = _redundant(n)
        qa = m.actuated_q(g.pick(ctx().assembled[n]))
        kw.pop("q0", None)
        return ctx().pkm.close_loops, (m, qa if not adv else g.near(qa, g.pick((1e-3, 1e-2)))), kw
    return ctx().pkm.close_loops, (m, g.value(qa, adv, g.pick((1e-3, 1e-2, 0.05, 0.2)))), kw


@entry("core.branch_seed")
def _branch_seed(g, adv):
    from pkm.core import branch_seed
    n, m = _mech(g, adv)
    branches = list(ctx().mech[n].spec.branches)
    return branch_seed, (m, g.pick(branches) if not adv else g.pick(branches + ["nope", None, 3, ""])), {}


def _q_entry(name: str, fn_name: str):
    @entry(name)
    def _e(g, adv):
        n, m = _mech(g, adv)
        return getattr(ctx().pkm, fn_name), (m, _q(g, n, adv)), {}
    return _e


for _fn in ("forward_jacobian", "inverse_jacobian", "twist_jacobian", "passive_map", "diagnose"):
    _q_entry(f"pkm.{_fn}", _fn)


@entry("pkm.velocities")
def _velocities(g, adv):
    n, m = _mech(g, adv)
    q = _q(g, n, adv and g.chance(0.5))
    qd = g.value(np.zeros(ctx().mech[n].na), adv and g.chance(0.7), 1.0)
    return ctx().pkm.velocities, (m, q, qd), {}


@entry("differential.actuation")
def _actuation(g, adv):
    from pkm.core.differential.velocity import actuation

    n, m = _mech(g, adv)
    q = _q(g, n, adv and g.chance(0.5)) if g.chance(0.7) else None
    rtol = g.pick((1e-7, 1e-9, 1e-3)) if not adv else g.pick((0.0, -1.0, 2.0, float("nan"), "1e-7", None, 1e-7))
    return actuation, (m, q), {"rtol": rtol}


@entry("pkm.load(package)")
def _load_package(g, adv):
    name = g.pick(("example-robot-data:cassie", "example-robot-data:cassie_v2"))
    if adv:
        name = g.pick(("example-robot-data:", "example-robot-data:Cassie", "example-robot-data:../cassie",
                       "example-robot-data:cassie\x00", "example-robot-data:cassie:v2", "example-robot-data::",
                       "example-robot-data:" + "c" * 10_000, "example-robot-data:/etc/passwd", name[::-1]))
    return ctx().pkm.load, (name,), {}


@entry("pkm.accelerations")
def _accelerations(g, adv):
    n, m = _mech(g, adv)
    nv, na = ctx().mech[n].nv, ctx().mech[n].na
    return ctx().pkm.accelerations, (m, _q(g, n, adv and g.chance(0.4)), g.value(np.zeros(nv), adv and g.chance(0.4)),
                                     g.value(np.zeros(na), adv and g.chance(0.4))), {}


@entry("pkm.inverse_velocities")
def _inverse_velocities(g, adv):
    n, m = _mech(g, adv)
    return ctx().pkm.inverse_velocities, (m, _q(g, n, adv and g.chance(0.5)),
                                          g.value(np.zeros(ctx().task[n].size), adv and g.chance(0.7), 1.0)), {}


@entry("pkm.inverse_accelerations")
def _inverse_accelerations(g, adv):
    n, m = _mech(g, adv)
    nv, nt = ctx().mech[n].nv, ctx().task[n].size
    return ctx().pkm.inverse_accelerations, (m, _q(g, n, adv and g.chance(0.4)),
                                             g.value(np.zeros(nv), adv and g.chance(0.4)),
                                             g.value(np.zeros(nt), adv and g.chance(0.4))), {}


@entry("pkm.task_acceleration")
def _task_acceleration(g, adv):
    n, m = _mech(g, adv)
    nv = ctx().mech[n].nv
    return ctx().pkm.task_acceleration, (m, _q(g, n, adv and g.chance(0.4)),
                                         g.value(np.zeros(nv), adv and g.chance(0.4)),
                                         g.value(np.zeros(nv), adv and g.chance(0.4))), {}


# mechanisms' closed forms -------------------------------------------------
def _params(g: Gen, n: str, adversarial: bool):
    """The reference design, or a random valid one, or (adversarial) a hostile object."""
    c = ctx()
    if adversarial and g.chance(0.05):
        return g.pick((None, "delta", 3, c.mech[n], c.mod[g.pick(c.names)].Params()))
    if g.chance(0.3):
        try:
            return c.mod[n].Params(**_param_kwargs(g, n, False))
        except c.pkm.PkmError:
            pass
    return c.mech[n].params


def _closed_forms(n: str):
    @entry(f"{n}.closed_form_ik")
    def _ik(g, adv):
        c = ctx()
        kw = {}
        if g.chance(0.2):
            branches = list(c.mech[n].spec.branches)
            kw["branch"] = g.pick(branches) if not adv else g.pick(branches + ["nope", 3, ("a",)])
        return c.mod[n].closed_form_ik, (_params(g, n, adv), _target(g, n, adv)), kw

    @entry(f"{n}.closed_form_configuration")
    def _conf(g, adv):
        c = ctx()
        _, m = _mech(g, adv, (n,))
        return c.mod[n].closed_form_configuration, (m, _target(g, n, adv)), {}

    if mechanism_module(n).closed_form_fk is not None:
        @entry(f"{n}.closed_form_fk")
        def _fk(g, adv):
            c = ctx()
            kw = {}
            if g.chance(0.2):
                kw["seed"] = _target(g, n, adv)
            qa = g.value(c.qa_ref[n], adv, g.pick((1e-3, 0.05, 0.3)))
            return c.mod[n].closed_form_fk, (_params(g, n, adv), qa), kw


@entry("delta.forward_kinematics")
def _delta_fk(g, adv):
    from pkm.mechanisms import delta
    return delta.forward_kinematics, (_params(g, "delta", adv), g.value(ctx().qa_ref["delta"], adv, 0.5)), \
        {"both": g.chance(0.5)}


@entry("delta.jacobian")
def _delta_jac(g, adv):
    from pkm.mechanisms import delta
    c = ctx()
    th = g.value(c.qa_ref["delta"], adv and g.chance(0.6), 0.3)
    kw = {}
    if g.chance(0.3):
        kw["p"] = g.value(c.y_ref["delta"], adv, 0.01)
    return delta.jacobian, (_params(g, "delta", adv), th), kw


@entry("rrr3.forward_kinematics")
def _rrr3_fk(g, adv):
    from pkm.mechanisms import rrr3
    kw = _solver_kwargs(g, adv, ("tol",))
    return rrr3.forward_kinematics, (_params(g, "rrr3", adv), g.value(ctx().qa_ref["rrr3"], adv, 0.5)), kw


@entry("rrr3.jacobians")
def _rrr3_jac(g, adv):
    from pkm.mechanisms import rrr3
    kw = {"branch": g.pick((None, 1, 5, "mode3"))} if not adv else {"branch": g.pick((0, 9, "mode0", None, 2.5, True))}
    return rrr3.jacobians, (_params(g, "rrr3", adv), _target(g, "rrr3", adv)), kw


@entry("rrr3.homogenized_jacobians")
def _rrr3_hjac(g, adv):
    from pkm.mechanisms import rrr3
    kw = {}
    if g.chance(0.3):
        kw["length"] = float(g.rng.uniform(0.01, 1)) if not adv else g.pick(ADV_NUMBERS + ADV_OBJECTS[:10])
    if g.chance(0.3):
        kw["reference"] = g.pick(rrr3.REFERENCES) if not adv else g.pick(("B", None, 3, ""))
    return rrr3.homogenized_jacobians, (_params(g, "rrr3", adv), _target(g, "rrr3", adv)), kw


@entry("rrr3.classify_singularity")
def _rrr3_classify(g, adv):
    from pkm.mechanisms import rrr3
    kw = {"tol": g.pick((1e-8, 1e-3)) if not adv else g.pick(ADV_NUMBERS + (None, "x"))} if g.chance(0.3) else {}
    return rrr3.classify_singularity, (_params(g, "rrr3", adv), _target(g, "rrr3", adv)), kw


@entry("hexapod.forward_kinematics")
def _hex_fk(g, adv):
    from pkm.mechanisms import hexapod as hx
    c = ctx()
    alphas = hx.paper_alphas(c.qa_ref["hexapod"])
    alphas = g.value(alphas, adv and g.chance(0.6), g.pick((1e-3, 0.02, 0.2)))
    kw = _solver_kwargs(g, adv, ("tol", "max_iter"))
    args = [_params(g, "hexapod", adv), alphas, g.maybe(0.0 if not g.chance(0.5) else float(g.rng.normal(0, 0.3)),
                                                        adv, 0.15)]
    if g.chance(0.2):
        args.append(g.value(hx.platform_points(hx.HexapodParams(), *pose_T_placement())[:3], adv, 0.01))
    return hx.forward_kinematics, tuple(args), kw


@entry("hexapod.assembly_modes")
def _hex_modes(g, adv):
    from pkm.mechanisms import hexapod as hx
    c = ctx()
    _, m = _mech(g, adv, ("hexapod",))
    kw = {"n_starts": int(g.rng.integers(1, 3))}
    kw.update(_solver_kwargs(g, adv, ("tol", "max_iter", "n_starts")))
    if "max_iter" not in kw:
        kw["max_iter"] = int(g.rng.integers(3, 15))
    return hx.assembly_modes, (m, g.value(c.qa_ref["hexapod"], adv, g.pick((1e-3, 0.02, 0.2)))), kw


def _pose(g: Gen, adversarial: bool):
    """(R, P) near the hexapod's pose T, or hostile."""
    from pkm.core.kinematics.task import zyx_matrix
    R0, P0 = pose_T_placement()
    R = R0 @ zyx_matrix(*g.near(np.zeros(3), g.pick((0.01, 0.1, 0.5))))
    P = g.near(P0, g.pick((0.001, 0.01, 0.05, 0.3)))
    if adversarial:
        if g.chance(0.5):
            R = g.pick((g.corrupt(R), R * 1.1, -R, R.T @ np.diag([1, 1, -1]), np.zeros((3, 3)), R[:2]))
        else:
            P = g.corrupt(P)
    return R, P


@entry("hexapod_indices.indices")
def _hex_indices(g, adv):
    from pkm.mechanisms.hexapod import indices as hi
    R, P = _pose(g, adv)
    kw = {}
    if g.chance(0.2):
        kw["point"] = g.pick(("O", "P")) if not adv else g.pick(("Q", None, 1))
    if g.chance(0.2):
        kw["length"] = float(g.rng.uniform(0.01, 1)) if not adv else g.pick(ADV_NUMBERS + ADV_OBJECTS[:8])
    return hi.indices, (_params(g, "hexapod", adv), R, P, g.maybe(float(g.rng.normal(0, 0.3)), adv, 0.2)), kw


@entry("hexapod_singularities.classify")
def _hex_classify(g, adv):
    from pkm.mechanisms.hexapod import singularities as hsg
    R, P = _pose(g, adv)
    kw = {}
    if g.chance(0.2):
        kw["tol"] = 1e-6 if not adv else g.pick(ADV_NUMBERS + (None,))
    if g.chance(0.2):
        kw["length"] = 0.05 if not adv else g.pick(ADV_NUMBERS + ADV_OBJECTS[:8])
    return hsg.classify, (_params(g, "hexapod", adv), R, P, g.maybe(float(g.rng.normal(0, 0.3)), adv, 0.2)), kw


def _baseline_nan_ok(res) -> bool:
    """NaN only in the baseline comparison: baseline values where ``baseline_ok`` is False, relative gains
    there and where the baseline's index is 0 (documented in ProfileOptimum); everything else finite."""
    r = getattr(res, "result", res)  # a BetaProfile holds its ProfileOptimum in .result
    ok = np.asarray(r.baseline_ok)
    base, gain = np.asarray(r.baseline_value), np.asarray(r.relative_gain)
    if r is not res and not (np.array_equal(np.asarray(res.base_value), base, equal_nan=True)
                             and np.array_equal(np.asarray(res.relative_gain), gain, equal_nan=True)):
        return False
    comparable = ok & (np.nan_to_num(base) != 0.0)
    if not (np.all(np.isnan(base[~ok])) and np.all(np.isfinite(base[ok]))
            and np.all(np.isnan(gain[~comparable])) and np.all(np.isfinite(gain[comparable]))):
        return False
    if r is not res:
        return (finite(dataclasses.replace(res, result=None, base_value=np.zeros(1), relative_gain=np.zeros(1)))
                and _baseline_nan_ok(r))
    return (finite(dataclasses.replace(r, pointwise=None, baseline_value=np.zeros(1), relative_gain=np.zeros(1)))
            and finite(r.pointwise))


@entry("hexapod_reconfigure.optimal_beta")
def _hex_beta(g, adv):
    from pkm.mechanisms.hexapod import reconfiguration as hr
    R, P = _pose(g, adv)
    kw = {}
    if g.chance(0.3):
        kw["index"] = g.pick(("w_rot", "w_tras")) if not adv else g.pick(("w", None, 0))
    if g.chance(0.2):
        kw["limits"] = g.pick(((-1.0, 1.0), (-0.2, 0.3))) if not adv else g.pick(((1.0, -1.0), (NAN, 1.0), None,
                                                                                   "ab", (0, 0), (-1e300, 1e300)))
    if g.chance(0.1):
        kw["tol"] = 1e-6 if not adv else g.pick(ADV_NUMBERS + (None,))
    return hr.optimal_beta, (_params(g, "hexapod", adv), R, P), kw


@entry("hexapod_reconfigure.beta_profile", sentinel=_baseline_nan_ok)
def _hex_profile(g, adv):
    from pkm.mechanisms.hexapod import reconfiguration as hr
    k = int(g.rng.integers(2, 5))
    R0, P0 = _pose(g, False)
    poses = [(R0, P0 + np.array([0.0, 0.0, 0.003 * j])) for j in range(k)]
    if adv:
        j = int(g.rng.integers(k))
        poses[j] = _pose(g, True) if g.chance(0.7) else g.hostile()
        if g.chance(0.1):
            poses = g.pick(([], None, "poses", poses[0]))
    kw = {}
    if g.chance(0.3):
        kw["rate_limit"] = float(g.rng.uniform(0.001, 0.1)) if not adv else g.pick(ADV_NUMBERS + (None,))
    if g.chance(0.2):
        kw["smoothness"] = float(g.rng.uniform(0, 10)) if not adv else g.pick(ADV_NUMBERS + (None,))
    return hr.beta_profile, (_params(g, "hexapod", adv), poses), kw


@entry("hexapod_reconfigure.reachable_intervals")
def _hex_intervals(g, adv):
    from pkm.mechanisms.hexapod import reconfiguration as hr
    R, P = _pose(g, adv)
    return hr.reachable_intervals, (_params(g, "hexapod", adv), R, P), {}


# generic reconfiguration layer ---------------------------------------------
def _index_fn(g: Gen, adversarial: bool):
    a, b, c = g.rng.normal(size=3)
    smooth = g.pick((lambda k, x: np.exp(-(x - a) ** 2) + 0.1 * np.sin(3 * x + b) + 0 * k,
                     lambda k, x: np.cos(x * (1 + abs(c))) + 2.0 + 0 * k,
                     lambda k, x: 1e-12 * (x - a) ** 2 + 0 * k))
    if not adversarial:
        return smooth
    return g.pick((lambda k, x: np.full(np.shape(x), np.nan), lambda k, x: 1.0 / (x - x),
                   lambda k, x: np.zeros(3), lambda k, x: "x", lambda k, x: None, lambda k, x: np.inf * x,
                   lambda k, x: np.exp(1e3 * x), smooth, smooth, 3))


@entry("redundant_parameter.maximise")
def _maximise(g, adv):
    from pkm.core.analysis import redundant_parameter
    n = int(g.rng.integers(1, 5))
    lo = g.rng.uniform(-2, 0, n)
    hi_ = lo + g.rng.uniform(0, 2, n)
    if adv and g.chance(0.5):
        lo, hi_ = g.pick(((g.corrupt(lo), hi_), (lo, g.corrupt(hi_)), (hi_ + 1, lo), (lo, hi_[:-1])))
    kw = {}
    if g.chance(0.2):
        kw[g.pick(("grid", "tol", "fd_step", "max_iter", "eta"))] = g.pick(ADV_NUMBERS + (None, 0, 1, -3, 2.5)) \
            if adv else None
        kw = {k: v for k, v in kw.items() if v is not None}
    return redundant_parameter.maximise, (_index_fn(g, adv), lo, hi_), kw


@entry("redundant_parameter.optimise_profile", sentinel=_baseline_nan_ok)
def _optimise_profile(g, adv):
    from pkm.core.analysis import redundant_parameter
    n = int(g.rng.integers(2, 6))
    lo = np.full(n, -1.0) + 0.1 * g.rng.normal(size=n)
    hi_ = lo + g.rng.uniform(0.2, 2, n)
    kw = {"rate_limit": float(g.rng.uniform(0.01, 0.5))}
    if adv:
        k = g.pick(("rate_limit", "smoothness", "baseline", "tol", "max_iter", "eta", "lower"))
        if k == "lower":
            lo = g.corrupt(lo)
        else:
            kw[k] = g.pick(ADV_NUMBERS + (None, "x", -1, 0))
    elif g.chance(0.3):
        kw["baseline"] = g.pick((None, 0.0, -0.5, 5.0))
    return redundant_parameter.optimise_profile, (_index_fn(g, adv), lo, hi_), kw


# indices ----------------------------------------------------------------
def _kappa_sentinel(res) -> bool:
    """``inf`` (never NaN) is the documented condition number of a singular matrix (or an unreachable point)."""
    if isinstance(res, dict):
        return all(_kappa_sentinel(v) for v in res.values())
    arr = np.asarray(res, dtype=float)
    return not np.any(np.isnan(arr)) and np.all(arr[~np.isfinite(arr)] > 0)


def _matrix(g: Gen, adversarial: bool):
    shape = g.pick(((3, 3), (6, 6), (2, 3), (4, 3, 3), (2, 2, 6, 6)))
    J = g.rng.normal(size=shape) * g.scale()
    if g.chance(0.2):
        J[..., -1, :] = J[..., 0, :]  # singular
    return g.corrupt(J) if adversarial else J


@entry("indices.condition_number", sentinel=_kappa_sentinel)
def _cond(g, adv):
    from pkm.core.differential import indices
    kind = g.pick(indices.KINDS) if not (adv and g.chance(0.2)) else g.pick(("3", None, 2, "FRO"))
    return indices.condition_number, (_matrix(g, adv), kind), {}


@entry("indices.inverse_condition")
def _icond(g, adv):
    from pkm.core.differential import indices
    return indices.inverse_condition, (_matrix(g, adv), g.pick(indices.KINDS)), {}


@entry("indices.manipulability")
def _manip(g, adv):
    from pkm.core.differential import indices
    return indices.manipulability, (_matrix(g, adv),), {}


@entry("indices.homogenize")
def _homog(g, adv):
    from pkm.core.differential import indices
    J0 = _matrix(g, False)
    J = g.corrupt(J0) if adv and g.chance(0.5) else J0
    L = float(g.rng.uniform(0.01, 2)) if not adv else g.pick(ADV_NUMBERS + ADV_OBJECTS[:10] + (0.1,))
    rows = g.pick((slice(0, 1), 0, [0], np.array([True] + [False] * (J0.shape[-2] - 1))))
    if adv and g.chance(0.2):
        rows = g.pick((10, "a", None, slice(None), [True]))
    return indices.homogenize, (J, rows, L), {}


def _ci_sentinel(res) -> bool:
    """``NaN`` only at unreachable nodes (mask ``reachable``)."""
    ci, reach = res
    ci = np.asarray(ci)
    return bool(np.all(np.isnan(ci[~reach])) and np.all(np.isfinite(ci[reach])))


@entry("rrr3_maps.condition_index", sentinel=_ci_sentinel)
def _rrr3_ci(g, adv):
    from pkm.mechanisms.rrr3 import workspace as rm
    c = ctx()
    base = c.y_ref["rrr3"][:2]
    m = int(g.rng.integers(1, 30))
    gx = base[0] + g.rng.normal(0, g.pick((0.01, 0.1, 0.5)), m)
    gy = base[1] + g.rng.normal(0, g.pick((0.01, 0.1, 0.5)), m)
    if adv:
        if g.chance(0.5):
            gx = g.corrupt(gx)
        else:
            gy = g.corrupt(gy)
    settings = {}
    if g.chance(0.3):
        settings = {"phi": float(g.rng.normal()) if not adv else g.hostile(), "kind": g.pick(rm.KINDS),
                    "branch": int(g.rng.integers(1, 9))}
    design = _params(g, "rrr3", adv)
    if adv and g.chance(0.1):
        design = g.pick((rm.Design(0.4, 0.4, 0.1, 1.0), None, "x"))

    def condition_index(design, gx, gy, **settings):
        return rm.condition_index(design, gx, gy, rm.CiSettings(**settings))
    return condition_index, (design, gx, gy), settings


@entry("rrr3_maps.ci_map")
def _rrr3_map(g, adv):
    from pkm.mechanisms.rrr3 import workspace as rm
    c = ctx()
    centre = c.y_ref["rrr3"][:2]
    half, step = float(g.rng.uniform(0.01, 0.3)), float(g.rng.uniform(0.02, 0.1))
    if adv:
        k = int(g.rng.integers(3))
        if k == 0:
            centre = g.corrupt(centre)
        elif k == 1:
            half = g.pick(ADV_NUMBERS + ADV_OBJECTS[:10])
        else:
            step = g.pick(ADV_NUMBERS + ADV_OBJECTS[:10] + (1e-9,))

    def grid_and_map(design, centre, half, step):
        m = rm.ci_map(design, rm.Grid.square(centre, half, step))
        return m.gci(), m.area_gci()
    return grid_and_map, (_params(g, "rrr3", adv), centre, half, step), {}


@entry("rrr3_maps.naive_condition_index")
def _rrr3_naive(g, adv):
    from pkm.mechanisms.rrr3 import workspace as rm
    y = _target(g, "rrr3", adv)

    def naive(design, y):
        v = rm.naive_condition_index(design, y)
        return None if math.isnan(v) else v  # NaN: documented for an unreachable pose
    return naive, (_params(g, "rrr3", adv), y), {}


@entry("delta_workspace.condition_numbers", sentinel=_kappa_sentinel)
def _delta_kappa(g, adv):
    from pkm.mechanisms.delta import workspace as dw
    c = ctx()
    pts = c.y_ref["delta"] + g.rng.normal(0, g.pick((0.01, 0.1, 0.5)), (int(g.rng.integers(1, 20)), 3))
    if adv:
        pts = g.corrupt(pts)
    kw = {}
    if g.chance(0.2):
        kw["kinds"] = g.pick((("2",), ("fro", "2"))) if not adv else g.pick(((), ("x",), None, "2", 3))
    if g.chance(0.2):
        kw["branch"] = g.pick(("knee_in", ("knee_in", "knee_out", "knee_in"))) if not adv else g.pick(("x", None, 3))

    def kappas(params, pts, **kw):
        K, _reach = dw.condition_numbers(params, pts, **kw)
        return K
    return kappas, (_params(g, "delta", adv), pts), kw


@entry("delta_design.radius_minimising_condition")
def _delta_radius(g, adv):
    from pkm.mechanisms.delta import design as dd
    c = ctx()
    p = g.value(c.y_ref["delta"], adv, g.pick((0.01, 0.05, 0.3)))
    kw = {"n_scan": int(g.rng.integers(2, 8))}
    if adv and g.chance(0.3):
        kw["n_scan"] = g.pick((0, -1, 1, None, 2.5, "3", 10**9))
    if g.chance(0.2):
        kw["kind"] = g.pick(("2", "fro")) if not adv else g.pick(("x", None))
    return dd.radius_minimising_condition, (_params(g, "delta", adv), p), kw


@entry("delta_design.reachable_radii")
def _delta_radii(g, adv):
    from pkm.mechanisms.delta import design as dd
    return dd.reachable_radii, (_params(g, "delta", adv), g.value(ctx().y_ref["delta"], adv, g.pick((0.01, 0.3)))), {}


# dynamics ----------------------------------------------------------------
def _prs3(g: Gen, adversarial: bool):
    from pkm.mechanisms.prs3.dynamics import Prs3Dynamics
    c = ctx()
    return c.lazy("prs3dyn", Prs3Dynamics)


@entry("Prs3Dynamics.forces")
def _prs3_forces(g, adv):
    y0 = np.array([0.81, 0.0, 0.0])
    y = g.value(y0, adv and g.chance(0.5), g.pick((0.01, 0.1, 0.5)))
    yd = g.value(np.zeros(3), adv and g.chance(0.3), 1.0)
    ydd = g.value(np.zeros(3), adv and g.chance(0.3), 1.0)
    args = [y, yd, ydd]
    if g.chance(0.3):
        args.append(g.value(np.zeros(6), adv, 10.0))
    return _prs3(g, adv).forces, tuple(args), {}


@entry("Prs3Dynamics.batch")
def _prs3_batch(g, adv):
    N = int(g.rng.integers(1, 40))
    Y = np.array([0.81, 0.0, 0.0]) + g.rng.normal(0, g.pick((0.01, 0.1, 0.5)), (N, 3))
    Yd, Ydd = g.rng.normal(size=(N, 3)), g.rng.normal(size=(N, 3))
    args = [Y, Yd, Ydd]
    if adv:
        k = int(g.rng.integers(3))
        args[k] = g.corrupt(args[k])
    kw = {}
    if g.chance(0.3):
        kw["wrench"] = g.value(np.zeros(6), adv, 10.0)
    if g.chance(0.3):
        kw["t"] = g.value(np.arange(N, dtype=float), adv, 0.0)
    if adv and g.chance(0.1):
        kw["chunk"] = g.pick((0, -1, None, 2.5))
    return _prs3(g, adv).batch, tuple(args), kw


@entry("Prs3Dynamics.jacobian")
def _prs3_jac(g, adv):
    return _prs3(g, adv).jacobian, (g.value(np.array([0.81, 0.0, 0.0]), adv, g.pick((0.01, 0.1, 0.5))),), {}


@entry("KhalilProjection.inverse_dynamics")
def _khalil(g, adv):
    from pkm.core.dynamics.projection import KhalilProjection
    c = ctx()
    n = g.pick(("delta", "prs3"))
    kp = c.lazy(f"khalil_{n}", lambda: KhalilProjection(c.mech[n]))
    m = c.mech[n]
    q = _q(g, n, adv and g.chance(0.4))
    v = g.value(np.zeros(m.nv), adv and g.chance(0.3), 1.0)
    a = g.value(np.zeros(m.nv), adv and g.chance(0.3), 1.0)
    kw = {"wrench": g.value(np.zeros(6), adv, 10.0)} if g.chance(0.3) else {}
    return kp.inverse_dynamics, (q, v, a), kw


@entry("pkm.inverse_dynamics")
def _inverse_dynamics(g, adv):
    c = ctx()
    n, m = _mech(g, adv)
    mm = c.mech[n]
    q = _q(g, n, adv and g.chance(0.4))
    v = g.value(np.zeros(mm.nv), adv and g.chance(0.3), 1.0)
    a = g.value(np.zeros(mm.nv), adv and g.chance(0.3), 1.0)
    kw: dict = {"method": g.pick(("auto", "khalil", "virtual_work") + (("newton", None) if adv else ()))}
    if g.chance(0.3):
        kw["wrench"] = g.value(np.zeros(6), adv, 10.0)
    if g.chance(0.3):
        frame = g.pick((mm.model.frames[mm.ee_frame].name, mm.model.frames[len(mm.model.frames) - 1].name)
                       + (("no_such_frame", 3) if adv else ()))
        kw["wrenches"] = {frame: g.value(np.zeros(6), adv, 10.0)} if not (adv and g.chance(0.2)) else g.hostile()
    return ctx().pkm.inverse_dynamics, (m, q, v, a), kw


@entry("dynamics.forward_dynamics")
def _fwd_dyn(g, adv):
    from pkm.core.dynamics.projection import forward_dynamics
    n, m = _mech(g, adv, ("delta", "prs3", "rrr3"))
    mm = ctx().mech[n]
    return forward_dynamics, (m, _q(g, n, adv and g.chance(0.4)), g.value(np.zeros(mm.nv), adv and g.chance(0.3)),
                              g.value(np.zeros(mm.na), adv and g.chance(0.3), 1.0)), {}


# the dynamic model, actuators, simulation (issue 29) -----------------------
def _drives(acts) -> list:
    """The numbers of drives (:class:`pkm.Actuator`), the reflected inertia and max effort with them; an ``inf``
    limit (documented: none) or servo stiffness (a rigid drive) read as 0, every other number must be finite."""
    from pkm.core.model.actuators import INFINITE, NUMBERS

    return [[0.0 if v == math.inf and f in (*INFINITE, "max_effort") else v
             for f, v in ((f, getattr(a, f)) for f in (*NUMBERS, "reflected_inertia", "max_effort"))] for a in acts]


def _drive_values(g: Gen, adversarial: bool, unknown: bool = True) -> dict:
    """Some fields of an actuator: plausible, or (adversarial) one of them hostile, an unknown one (if ``unknown``:
    not for a constructor, where Python refuses it), or a set that contradicts itself (peak below continuous), or
    overflows (huge rotor inertia and ratio)."""
    kw: dict = {}
    for f in g.rng.permutation(("rotor_inertia", "gear_ratio", "armature", "viscous", "coulomb", "effort_limit",
                                "peak_effort", "velocity_limit"))[:int(g.rng.integers(0, 5))]:
        kw[str(f)] = {"rotor_inertia": 1e-5, "gear_ratio": 50.0, "armature": 1e-3, "viscous": 0.02, "coulomb": 0.1,
                      "effort_limit": 20.0, "peak_effort": 60.0, "velocity_limit": 8.0}[str(f)] * \
            float(g.rng.uniform(0.1, 3.0))
    if "peak_effort" in kw and "effort_limit" in kw:
        kw["peak_effort"] = max(kw["peak_effort"], kw["effort_limit"])
    if adversarial:
        r = int(g.rng.integers(5))
        f = g.pick(("rotor_inertia", "gear_ratio", "armature", "viscous", "coulomb", "effort_limit", "peak_effort",
                    "velocity_limit"))
        if r <= 1:
            kw[f] = g.pick(ADV_NUMBERS + ADV_OBJECTS[:12] + (np.float64(-2.0), np.int64(0), 10**400))
        elif r == 2 and unknown:
            kw[g.pick(("inertia", "damping", "", "joint", "gear"))] = 1.0
        elif r <= 3:
            kw.update(effort_limit=10.0, peak_effort=g.pick((5.0, 0.0, NAN, -10.0)))
        else:
            kw.update(rotor_inertia=g.pick((1e300, 1e200, 1e10)), gear_ratio=g.pick((1e300, 1e200, 1e10)),
                      armature=g.pick((0.0, 1e308)))
    return kw


def _passive_name(mech) -> str:
    """A joint of ``mech`` that is not actuated."""
    return next(j for j in mech.joints if j not in mech.actuated_names)


@entry("Actuator")
def _actuator(g, adv):
    from pkm import Actuator

    joint = g.pick(("motor_1", "slider_2")) if not (adv and g.chance(0.1)) else g.hostile()
    kw = _drive_values(g, adv, unknown=False)

    def make(joint, **kw):
        return _drives([Actuator(joint, **kw)])
    return make, (joint,), kw


@entry("pkm.with_actuators")
def _with_actuators(g, adv):
    from pkm import Actuator

    c = ctx()
    n, m = _mech(g, adv, ("rrr3", "delta", "prs3", "gough_stewart"))
    mm = c.mech[n]
    joint = g.pick(mm.actuated_names)
    if g.chance(0.3):
        try:
            value: object = Actuator(joint, **_drive_values(g, False))
        except c.pkm.PkmError:
            value = {}
    else:
        value = _drive_values(g, adv)
    drives: object = {joint: value}
    if adv and g.chance(0.3):
        drives = g.pick(({"no_such_joint": {}}, {_passive_name(mm): {}}, [joint],
                         {joint: g.hostile()}, g.hostile(), {3: {}}, {joint: {"gear_ratio": "50"}}))

    def run(mech, drives):
        new = c.pkm.with_actuators(mech, drives)
        return _drives(new.actuators), c.pkm.mass_matrix(new, new.q_reference)
    return run, (m, drives), {}


@entry("spec.actuators")
def _spec_actuators(g, adv):
    """The spec's ``[actuators.<joint>]`` tables, written into the spec's text, parsed and built into the model."""
    c = ctx()
    n = g.pick(("rrr3", "delta", "prs3"))
    mm = c.mech[n]
    joint = g.pick(mm.actuated_names)
    lines = [f"{k} = {float(v)!r}" for k, v in _drive_values(g, False).items()]
    table = f"\n[actuators.{joint}]\n" + "\n".join(lines) + "\n"
    if adv:
        r = int(g.rng.integers(8))
        key = g.pick(("rotor_inertia", "gear_ratio", "viscous", "effort_limit", "peak_effort", "velocity_limit"))
        if r == 0:
            table += f"{key} = {g.pick(('nan', 'inf', '-inf', '-1.0', '0', '1e308', '-0.0', '1e-320'))}\n"
        elif r == 1:
            bad = g.pick(('"50"', "true", "[1.0]", "{ a = 1 }", "1979-05-27", "0x10"))
            table += f"{key} = {bad}\n"
        elif r == 2:
            table += f"{g.pick(('inertia', 'joint', 'gear', 'damping'))} = 1.0\n"
        elif r == 3:
            table = f"\n[actuators.{g.pick(('no_such_joint', _passive_name(mm)))}]\n" \
                "gear_ratio = 2.0\n"
        elif r == 4:
            table = g.pick(("\nactuators = 3\n", "\nactuators = [1, 2]\n", f"\n[actuators]\n{joint} = 5.0\n",
                            "\n[[actuators]]\ngear_ratio = 1.0\n", f"\n[actuators.{joint}.sub]\na = 1.0\n"))
        elif r == 5:
            table += table  # the same table twice
        elif r == 6:
            table = f"\n[actuators.{joint}]\neffort_limit = 10.0\npeak_effort = 5.0\n"
        else:
            table = f"\n[actuators.{joint}]\nrotor_inertia = 1e300\ngear_ratio = 1e300\n"

    def parse_and_build(spec_text):
        from pkm.core.model.spec import ClosureSpec
        spec = ClosureSpec.from_toml(spec_text)
        mech = c.pkm.from_strings(c.urdf[n], spec)
        return _drives(mech.actuators), sorted(spec.actuators)  # (the tables' inf limits: documented, none)
    return parse_and_build, (c.spec[n] + table,), {}


def _dyn_state(g: Gen, adversarial: bool, names=None):
    """(name, mechanism or hostile, q, actuated rates) for the dynamic model."""
    n, m = _mech(g, adversarial, names)
    mm = ctx().mech[n]
    q = _q(g, n, adversarial and g.chance(0.4))
    qd = g.value(np.zeros(mm.na if g.chance(0.85) else mm.nv), adversarial and g.chance(0.4), 1.0)
    return n, m, q, qd


def _rtol_kwargs(g: Gen, adversarial: bool, names=("rtol",)) -> dict:
    kw: dict = {}
    if g.chance(0.25):
        k = g.pick(names)
        kw[k] = {"rtol": 1e-9, "coulomb_velocity": 1e-3, "mu": 1e-9, "max_iter": 100}[k] if not adversarial else \
            g.pick(ADV_NUMBERS + (None, "1e-9", 0, 1.5, -3, 2.5))
    return kw


@entry("pkm.actuator_model")
def _actuator_model(g, adv):
    _, m, q, qd = _dyn_state(g, adv)
    return ctx().pkm.actuator_model, (m, q, qd), _rtol_kwargs(g, adv, ("rtol", "coulomb_velocity"))


@entry("ActuatorSpaceModel")
def _actuator_model_methods(g, adv):
    """The model's methods (efforts, accelerations, joint accelerations, energy) at a valid state, their
    argument valid or hostile."""
    c = ctx()
    n, _, q, qd = _dyn_state(g, False)
    na = c.mech[n].na
    method = g.pick(("efforts", "accelerations", "joint_accelerations", "kinetic_energy"))
    arg = g.value(np.zeros(na), adv, g.pick((0.1, 1.0, 100.0)))
    kw = {"friction": g.chance(0.5)} if method == "accelerations" else {}

    def run(mech, q, qd, arg, **kw):
        model = c.pkm.actuator_model(mech, q, qd)
        return model.kinetic_energy if method == "kinetic_energy" else getattr(model, method)(arg, **kw)
    return run, (c.mech[n], q, qd, arg), kw


@entry("pkm.mass_matrix")
def _mass_matrix(g, adv):
    _, m, q, _ = _dyn_state(g, adv)
    return ctx().pkm.mass_matrix, (m, q), {}


@entry("pkm.gravity_efforts")
def _gravity_efforts(g, adv):
    _, m, q, _ = _dyn_state(g, adv)
    return ctx().pkm.gravity_efforts, (m, q), {}


@entry("pkm.bias_efforts")
def _bias_efforts(g, adv):
    _, m, q, qd = _dyn_state(g, adv)
    return ctx().pkm.bias_efforts, (m, q, qd), {}


@entry("pkm.coriolis_matrix")
def _coriolis(g, adv):
    _, m, q, qd = _dyn_state(g, adv, ("rrr3", "delta", "prs3"))
    return ctx().pkm.coriolis_matrix, (m, q, qd), _rtol_kwargs(g, adv)


@entry("pkm.operational_space")
def _operational_space(g, adv):
    _, m, q, qd = _dyn_state(g, adv)
    return ctx().pkm.operational_space, (m, q, qd), _rtol_kwargs(g, adv)


@entry("pkm.regressor")
def _regressor(g, adv):
    n, m, q, qd = _dyn_state(g, adv)
    qdd = g.value(np.zeros(ctx().mech[n].na), adv and g.chance(0.4), 1.0)
    return ctx().pkm.regressor, (m, q, qd, qdd), {}


_BASES: dict = {}


@entry("pkm.estimate")
def _estimate(g, adv):
    c = ctx()
    _, m = _mech(g, adv, ("rrr3",))
    mm = c.mech["rrr3"]
    n = 30
    Q = np.repeat(mm.q_reference[None, :], n, axis=0)
    arrays = [Q, g.rng.standard_normal((n, 3)), g.rng.standard_normal((n, 3)), g.rng.standard_normal((n, 3))]
    if adv:
        k = int(g.rng.integers(0, 4))
        arrays[k] = g.value(arrays[k], True, 1.0)
    if "rrr3" not in _BASES:  # (computed once: the estimate, not the base parameters, is what this entry tries)
        _BASES["rrr3"] = c.pkm.base_parameters(mm, precise=False)
    return c.pkm.estimate, (m, *arrays), {"weighted": g.chance(0.5), "base": _BASES["rrr3"]}


@entry("pkm.base_parameters")
def _base_parameters(g, adv):
    _, m = _mech(g, adv, ("rrr3",))  # (the cheapest: 82 parameters; its least sample count 28)
    samples = g.pick((28, 40, 5)) if not adv or g.chance(0.5) else g.pick(ADV_NUMBERS + (0, -3, 2.5, "7", True))
    # (two seeds: random_states keeps the last four draws, and closing the loops of 40 states is most of a call)
    return ctx().pkm.base_parameters, (m, samples), {"seed": g.pick((0, 1)),
                                                     "precise": g.chance(0.1)}  # (the 50-digit route: 0.3 s)


@entry("pkm.regressor_batch")
def _regressor_batch(g, adv):
    n, m, q, qd = _dyn_state(g, adv, ("delta", "prs3"))
    mm = ctx().mech[n]
    k = int(g.rng.integers(1, 4))
    Q, QD, QDD = [q] * k, [qd] * k, g.rng.standard_normal((k, mm.na))  # (lists: q, qd may be hostile objects)
    if adv and g.chance(0.5):
        QDD = g.value(QDD, True, 1.0)
    backend = g.pick(("auto", "python", "c")) if not adv or g.chance(0.5) else g.pick(("fortran", 3, None))
    return ctx().pkm.regressor_batch, (m, Q, QD, QDD), {"backend": backend}


@entry("pkm.capability")
def _capability(g, adv):
    _, m, q, _ = _dyn_state(g, adv, ("delta", "prs3", "rrr3", "gough_stewart"))
    kind = g.pick(("wrench", "twist", "acceleration")) if not adv or g.chance(0.5) else \
        g.pick(("power", 3, None, np.zeros(3)))  # (an array: ``kind in KINDS`` raised numpy's ValueError)
    return ctx().pkm.capability, (m, q, kind), {"gravity": g.chance(0.7)}


@entry("pkm.calibration_parameters")
def _calibration_parameters(g, adv):
    """The unknowns of a measurement model (cheap: names only); adversarial, a configuration or a hostile object in
    ``kind``'s place (an array raised numpy's ValueError), or hostile joint and sensor names."""
    c = ctx()
    n, m = _mech(g, adv, ("delta", "prs3", "rrr3"))
    kind = g.pick(("pose", "position", "planar"))
    kw: dict = {"origins": g.pick(("all", "position"))}
    if adv:
        r = int(g.rng.integers(3))
        if r == 0:
            kind = g.pick((c.mech[n].q_reference, "Pose", "volume") + ADV_OBJECTS[:8])
        elif r == 1:
            kw[g.pick(("joints", "sensors"))] = g.pick((["no_such_joint"], "motor_1", c.mech[n].q_reference, [3]))
        else:
            kw["origins"] = g.hostile()
    return c.pkm.calibration_parameters, (m, kind), kw


def _springs_kw(g: Gen, adversarial: bool, n: str) -> dict:
    """``joints=`` for pkm.stiffness: every actuated joint a stiffness (revolute N m/rad, prismatic N/m), or some
    left out (locked), or hostile values and names."""
    mm = ctx().mech[n]
    joints: dict = {j: float(10.0 ** g.rng.uniform(2, 7)) for j in mm.actuated_names if g.chance(0.8)}
    if adversarial:
        what = int(g.rng.integers(0, 4))
        if what == 0 and joints:
            joints[g.pick(list(joints))] = g.hostile()
        elif what == 1:
            joints[g.pick(("nope", "", mm.actuated_names[0] + "x"))] = 1.0
        elif what == 2:
            return {"joints": g.hostile()}
        else:
            return {"joints": joints, g.pick(("links", "rtol")): g.hostile()}
    return {"joints": joints}


def _inf_along_rigid(res) -> bool:
    """The principal stiffnesses are ``inf`` along rigid directions (documented); the rest is finite."""
    compliance, (k, directions), displacement = res
    return bool(np.all(np.isfinite(compliance)) and np.all(np.isfinite(displacement))
                and np.all(np.isfinite(directions)) and not np.any(np.isnan(k)))


@entry("pkm.stiffness", sentinel=_inf_along_rigid)
def _stiffness(g, adv):
    """The stiffness, its matrix or principal values, and a deflection under a random wrench."""
    n, m, q, _ = _dyn_state(g, adv, ("delta", "prs3", "rrr3", "gough_stewart"))
    kw = _springs_kw(g, adv, n)
    W = g.value(g.rng.normal(size=6) * 10.0 ** g.rng.uniform(-1, 2), adv and g.chance(0.4), 100.0)

    def run(m, q, W, **kw):
        K = ctx().pkm.stiffness(m, q, **kw)
        return K.compliance, K.principal("force"), K.deflection(W).displacement
    return run, (m, q, W), kw


@entry("Stiffness.loaded")
def _loaded_stiffness(g, adv):
    """The tangent stiffness under a random wrench (rigid links); on the Gough-Stewart, at times, its links as beams
    of their capsules and a material (random or hostile moduli)."""
    n, m, q, _ = _dyn_state(g, adv, ("delta", "prs3", "rrr3", "gough_stewart"))
    kw = _springs_kw(g, adv, n)
    W = g.value(g.rng.normal(size=6) * 10.0 ** g.rng.uniform(-1, 2), adv and g.chance(0.4), 100.0)
    E = (g.hostile() if adv and g.chance(0.3) else float(10.0 ** g.rng.uniform(9, 12))) \
        if n == "gough_stewart" and "links" not in kw and g.chance(0.3) else None

    def run(m, q, W, E=None, **kw):
        if E is not None:
            K = ctx().pkm.stiffness(m, q, links=ctx().pkm.Material(E=E), **kw)
            return K.compliance
        return ctx().pkm.stiffness(m, q, **kw).loaded(W).compliance
    return run, (m, q, W), {**kw, "E": E}


@entry("pkm.clearance")
def _clearance(g, adv):
    """The signed distances and the smallest's gradient (a design without collision geometry: refused)."""
    _, m, q, _ = _dyn_state(g, adv, ("gough_stewart", "delta"))

    def run(m, q):
        c = ctx().pkm.clearance(m, q)
        return np.array(list(c.pairs.values())), c.minimum, c.gradient
    return run, (m, q), {}


@entry("clearance_map")
def _clearance_map(g, adv):
    """The smallest distance over several configurations, some hostile."""
    from pkm.core.collision import clearance_map

    n, m = _mech(g, adv, ("gough_stewart",))
    nodes = [_q(g, n, adv and g.chance(0.5)) for _ in range(int(g.rng.integers(1, 4)))]
    return clearance_map, (m, g.maybe(nodes, adv)), {}


@entry("pkm.vibration_modes")
def _vibration_modes(g, adv):
    n, m, q, _ = _dyn_state(g, adv, ("delta", "prs3", "rrr3", "gough_stewart"))
    return ctx().pkm.vibration_modes, (m, q), _springs_kw(g, adv, n)


@entry("pkm.measurements")
def _measurements(g, adv):
    """A table of the Delta's: time, q.<joint>, tau.<joint> (a slow sine), with hostile cells, columns, times."""
    c = ctx()
    _, m = _mech(g, adv, ("delta",))
    mm = c.mech["delta"]
    n = int(g.pick((400, 60, 3))) if adv else 400
    t = np.arange(n) * 0.002
    cols = {"time": t}
    for k, j in enumerate(mm.actuated_names):
        cols[f"q.{j}"] = mm.actuated_q(mm.q_reference)[k] + 0.05 * np.sin(3 * t + k)
        cols[f"tau.{j}"] = np.cos(3 * t)
    if adv:
        key = g.pick(list(cols))
        what = int(g.rng.integers(0, 4))
        if what == 0:
            cols.pop(key)
        elif what == 1:
            cols[key] = g.value(cols[key], True, 1.0)
        elif what == 2:
            cols[key] = cols[key][::-1].copy()
        else:
            cols[key] = cols[key] * 57.3
    cutoff = g.pick((None, 5.0, 20.0)) if not adv or g.chance(0.5) else g.pick(ADV_NUMBERS + (0.0, 1e9))
    return c.pkm.measurements, (m, cols), {"cutoff": cutoff}


def _forward_args(g: Gen, adversarial: bool, names=None):
    """(mechanism, q, v, tau): ``v`` consistent with ``q`` where it is assembled (or zero), or hostile."""
    c = ctx()
    n, m, q, qd = _dyn_state(g, adversarial, names)
    mm = c.mech[n]
    v = np.zeros(mm.nv)
    if not adversarial:
        try:
            v = c.pkm.passive_map(mm, q) @ qd[mm.act_v] if qd.shape == (mm.nv,) else c.pkm.passive_map(mm, q) @ qd
        except (c.pkm.PkmError, ValueError):
            pass
    elif g.chance(0.5):
        v = g.corrupt(v) if g.chance(0.5) else qd
    tau = g.value(np.zeros(mm.na), adversarial and g.chance(0.4), g.pick((0.1, 10.0, 1e3)))
    return m, q, v, tau


@entry("pkm.forward_dynamics")
def _forward_dynamics(g, adv):
    m, q, v, tau = _forward_args(g, adv)
    kw: dict = {"method": g.pick(("model", "constraint_dynamics") + (("khalil", None, 3, "") if adv else ()))}
    if kw["method"] == "constraint_dynamics" or (adv and g.chance(0.2)):
        kw.update(_rtol_kwargs(g, adv, ("mu",)))
    return ctx().pkm.forward_dynamics, (m, q, v, tau), kw


@entry("pkm.constraint_dynamics")
def _constraint_dynamics(g, adv):
    m, q, v, tau = _forward_args(g, adv, ("rrr3", "delta", "prs3", "gough_stewart", "hexapod"))
    return ctx().pkm.constraint_dynamics, (m, q, v, tau), _rtol_kwargs(g, adv, ("mu", "max_iter"))


def _driven(n: str):
    """``n`` with drives that bind: rotor inertia, friction, peak effort and speed limits (made once)."""
    c = ctx()

    def make():
        mech = c.mech[n]
        drives = {j: {"rotor_inertia": 1e-5, "gear_ratio": 20.0, "viscous": 0.05, "coulomb": 0.05,
                      "effort_limit": 2.0, "peak_effort": 5.0, "velocity_limit": 3.0} for j in mech.actuated_names}
        return c.pkm.with_actuators(mech, drives)
    return c.lazy(f"driven:{n}", make)


def _controller(g: Gen, adversarial: bool, na: int):
    """A controller ``(t, q, v) -> efforts``: a PD-like law, or (adversarial) one that raises, returns the wrong
    shape or type, NaN, or efforts of absurd size."""
    gain = float(g.pick((0.1, 1.0, 50.0)))
    ref = None

    def pd(t, q, v):
        nonlocal ref
        ref = q.copy() if ref is None else ref
        return -gain * v[:na] - gain * (q[:na] - ref[:na])

    if not adversarial:
        return g.pick((pd, lambda t, q, v: np.full(na, 0.1 * math.sin(50 * t)), lambda t, q, v: [0.0] * na))
    return g.pick((lambda t, q, v: 1 / 0, lambda t, q, v: np.zeros(na + 1), lambda t, q, v: np.zeros((na, 1)),
                   lambda t, q, v: np.full(na, np.nan), lambda t, q, v: "efforts", lambda t, q, v: None,
                   lambda t, q, v: np.full(na, 1e300), lambda t, q, v: np.full(na, 1e12), lambda t, q, v: [None] * na,
                   lambda t, q, v: np.full(na, np.inf) if t > 0 else np.zeros(na), lambda t, q, v: 1.0,
                   lambda t, q, v: q.__setitem__(0, np.nan), lambda: 0.0, lambda t, q, v: {"tau": 0},
                   lambda t, q, v: np.zeros(na, dtype=complex) + 1j, pd, 3, "pd"))


def _torques(g: Gen, adversarial: bool, na: int):
    k = int(g.rng.integers(1, 5))
    times = np.sort(g.rng.uniform(0.0, 0.005, k))
    times += np.arange(k) * 1e-4  # strictly increasing
    table = g.rng.normal(0.0, g.pick((0.1, 1.0)), (k, na))
    if not adversarial:
        return times, table
    r = int(g.rng.integers(6))
    if r == 0:
        return times[::-1].copy() if k > 1 else np.array([0.0, 0.0]), table
    if r == 1:
        return g.corrupt(times), table
    if r == 2:
        return times, g.corrupt(table)
    if r == 3:
        return np.array([0.0, 0.001, 0.001]), np.zeros((3, na))
    if r == 4:
        return g.pick(((times,), (times, table, table), times, None, "t", [[0.0, [0.0] * na]]))
    return g.pick(((np.zeros(0), np.zeros((0, na))), (times, table.T), (np.array([0.0, np.inf]), np.zeros((2, na)))))


@entry("pkm.simulate")
def _simulate(g, adv):
    c = ctx()
    n, m = _mech(g, adv, ("rrr3", "delta", "prs3", "delta", "rrr3", "gough_stewart", "hexapod"))
    mm = c.mech[n]
    if g.chance(0.3) and n != "hexapod" and m is mm:
        m = mm = _driven(n)
    kw: dict = {"duration": float(g.pick((1e-3, 2e-3, 3e-3))), "dt": 1e-3, "max_steps": 1000}  # (no long runs)
    if g.chance(0.5):
        kw["q0"] = g.pick((_q(g, n, False), mm.actuated_q(g.pick(c.assembled[n])), mm.q_reference))
    if g.chance(0.4):
        kw["v0"] = g.near(np.zeros(mm.na if g.chance(0.8) else mm.nv), g.pick((0.01, 0.5)))
        if g.chance(0.2) and "q0" in kw and kw["q0"].shape == (mm.nq,):  # rates consistent with q0, all joints
            try:
                kw["v0"] = c.pkm.passive_map(mm, kw["q0"]) @ g.near(np.zeros(mm.na), 0.5)
            except c.pkm.PkmError:
                pass
    if g.chance(0.4):
        kw["controller"] = _controller(g, False, mm.na)
    elif g.chance(0.3):
        kw["torques"] = _torques(g, False, mm.na)
    if g.chance(0.3) and n not in ("hexapod", "gough_stewart"):  # (Radau: the cheaper mechanisms)
        kw["method"] = "radau"
    for flag in ("friction", "saturate", "limits"):
        if g.chance(0.15):
            kw[flag] = g.chance(0.5)
    if adv:
        what = g.pick(("q0", "v0", "duration", "dt", "controller", "controller", "torques", "torques", "both",
                       "method", "tols", "max_steps", "steps_beyond"))
        if what == "q0":
            kw["q0"] = g.corrupt(g.pick((mm.q_reference, mm.actuated_q(mm.q_reference))))
        elif what == "v0":
            kw["v0"] = g.corrupt(np.zeros(mm.na))
        elif what in ("duration", "dt"):
            kw[what] = g.pick(ADV_NUMBERS + ADV_OBJECTS[:10] + (1e-9, 1e-12, 10.0, np.array([1e-3])))
        elif what == "controller":
            kw.pop("torques", None)
            kw["controller"] = _controller(g, True, mm.na)
        elif what == "torques":
            kw.pop("controller", None)
            kw["torques"] = _torques(g, True, mm.na)
        elif what == "both":
            kw["controller"], kw["torques"] = _controller(g, False, mm.na), _torques(g, False, mm.na)
        elif what == "method":
            kw["method"] = g.pick(("RK4", "euler", "", None, 3, ["rk4"]))
        elif what == "tols":
            kw[g.pick(("singular_tol", "coulomb_velocity", "step_tol"))] = g.pick(ADV_NUMBERS + (None, "1e-3", 1.0))
        elif what == "max_steps":
            kw["max_steps"] = g.pick((0, -1, 2.5, True, None, "10", 10**400, np.int64(5), 1))
        else:  # a run beyond max_steps (given, or the default)
            kw.update(duration=g.pick((1e6, 1e300, 1e-2)), dt=g.pick((1e-3, 1e-9, 5e-324)), max_steps=g.pick((2, 5)))
            if kw["duration"] > 1.0 and g.chance(0.5):
                del kw["max_steps"]

    def run(mech, **kw):
        sim = c.pkm.simulate(mech, **kw)
        return sim, sim.energy
    return run, (m,), kw


@entry("screws.transform")
def _screw_transform(g, adv):
    from pkm.core.differential import screws
    s = g.rng.normal(size=g.pick(((6,), (4, 6))))
    R = np.eye(3)
    t = g.rng.normal(size=3)
    if adv:
        k = int(g.rng.integers(3))
        s, R, t = (g.corrupt(s), R, t) if k == 0 else (s, g.corrupt(R), t) if k == 1 else (s, R, g.corrupt(t))
    return screws.transform, (s, R, t), {}


for _n in mechanism_names():
    _closed_forms(_n)


