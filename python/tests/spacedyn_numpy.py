"""An independent reference evaluator for SpaceDyn robot files (the MATLAB toolbox of the Space
Robotics Lab, Tohoku University), in NumPy only: it reads the subset of MATLAB that an exported
`function LP = ..._LP()` / `function SV = ..._SV()` file uses and evaluates the model from
SpaceDyn's own definitions (calc_aa, calc_pos, rpy2dc, cx/cy/cz, calc_jte/calc_jre, f_kin_e,
calc_hh, calc_gj), never from kdl_space's code.

Conventions (SpaceDyn's):
- links 1..n (n = LP.num_q), link 0 the base; link i hangs from link BB(i) < i by joint i, which
  turns about ('R') or slides along ('P') the z axis of link i's frame;
- cx/cy/cz are direction cosine matrices (transposed rotations), rpy2dc(r,p,y) = cz(y) cy(p) cx(r),
  so rpy2dc(r,p,y)' = Rx(r) Ry(p) Rz(y);
- A_i maps link-i-frame vectors to the inertial frame; RR(:,i) is link i's centroid;
- the generalized velocity is (v0, w0, qd): base-centroid velocity and base angular velocity, both
  inertial, then the joint rates;
- end point k (1-based, as SpaceDyn's num_e) is the k-th link i with SE(i) = 1.

Python indices are 0-based: link i of SpaceDyn is column i-1 of RR, entry i-1 of AA.
"""
import os
import re

import numpy as np

EZ = np.array([0.0, 0.0, 1.0])


class SpaceDynParseError(ValueError):
    """A line of a SpaceDyn .m file outside the subset this reader accepts (the message names the
    file and the 1-based line)."""


# ----------------------------------------------------------------------------------------------
# rotations (SpaceDyn's cx, cy, cz, rpy2dc, tilde)

def cx(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])


def cy(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def cz(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy2dc(roll, pitch=None, yaw=None):
    """SpaceDyn's rpy2dc: cz(yaw) cy(pitch) cx(roll); rpy2dc([r p y]) also accepted."""
    if pitch is None and yaw is None:
        roll, pitch, yaw = np.asarray(roll, dtype=float).reshape(3)
    return cz(yaw) @ cy(pitch) @ cx(roll)


def tilde(a):
    """The cross-product matrix: tilde(a) @ b = a x b."""
    a = np.asarray(a, dtype=float).reshape(3)
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


# ----------------------------------------------------------------------------------------------
# the .m reader

_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?\Z")
_FUNCTION = re.compile(r"function\s+([A-Za-z]\w*)\s*=\s*([A-Za-z]\w*)\s*(?:\(\s*\))?\s*;?\Z")
_ASSIGN = re.compile(r"([A-Za-z]\w*)\.([A-Za-z]\w*)\s*(?:\(([^()]*)\))?\s*=\s*(.*?)\s*;?\Z", re.S)
_ZEROS = re.compile(r"zeros\s*\(([^()]*)\)\Z")
_STRING = re.compile(r"'((?:[^']|'')*)'\Z")


def _strip_comment(line):
    """The line without its % comment (a % inside a '...' string is kept), and the bracket depth
    change of what is left."""
    out, in_string, depth = [], False, 0
    for ch in line:
        if in_string:
            out.append(ch)
            if ch == "'":
                in_string = False  # '' (an escaped quote) reopens at once on the next char
            continue
        if ch == "%":
            break
        if ch == "'":
            in_string = True
        elif ch == "[":
            depth += 1
        elif ch == "]":
            depth -= 1
        out.append(ch)
    return "".join(out).rstrip(), depth, in_string


def _statements(text, where):
    """(first line number, statement text) of the file; a statement whose [ ] is still open at the
    end of a line continues on the next (the line break being a row separator)."""
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        start = i + 1
        body, depth, open_string = _strip_comment(lines[i])
        if open_string:
            raise SpaceDynParseError(f"{where}:{start}: unterminated string: {lines[i]!r}")
        parts = [body]
        while depth > 0:
            i += 1
            if i >= len(lines):
                raise SpaceDynParseError(f"{where}:{start}: '[' not closed before the end of the file")
            more, d, open_string = _strip_comment(lines[i])
            if open_string:
                raise SpaceDynParseError(f"{where}:{i + 1}: unterminated string: {lines[i]!r}")
            parts.append(more)
            depth += d
        if depth < 0:
            raise SpaceDynParseError(f"{where}:{i + 1}: unbalanced ']': {lines[i]!r}")
        statement = "\n".join(parts).strip()
        if statement:
            yield start, statement
        i += 1


def _number(token, where, line):
    if not _NUMBER.match(token):
        raise SpaceDynParseError(f"{where}:{line}: not a finite number: {token!r}")
    return float(token)


def _matrix(body, where, line):
    """A literal [ ... ]: rows separated by ';' or line breaks, entries by blanks or ','."""
    inner = body[1:-1]
    if "[" in inner or "]" in inner:
        raise SpaceDynParseError(f"{where}:{line}: nested brackets are not accepted: {body!r}")
    rows = []
    for row in re.split(r"[;\n]", inner):
        tokens = [t for t in re.split(r"[\s,]+", row.strip()) if t]
        if tokens:
            rows.append([_number(t, where, line) for t in tokens])
    if not rows:
        return np.zeros((0, 0))
    if len({len(r) for r in rows}) != 1:
        raise SpaceDynParseError(f"{where}:{line}: rows of different lengths: {body!r}")
    return np.array(rows, dtype=float)


def _dims(text, where, line, what):
    out = []
    for t in text.split(","):
        t = t.strip()
        if not re.fullmatch(r"\d+", t):
            raise SpaceDynParseError(f"{where}:{line}: {what}: {t!r} is not a non-negative integer")
        out.append(int(t))
    return out


def _value(rhs, var, field, values, where, line):
    if rhs.startswith("[") and rhs.endswith("]"):
        return _matrix(rhs, where, line)
    m = _STRING.match(rhs)
    if m:
        return m.group(1).replace("''", "'")
    if rhs.startswith("{") and rhs.endswith("}"):  # a cell of names (LP.link_names): kept as a list of str
        cells = re.findall(r"'((?:[^']|'')*)'\s*(?:,|$)", rhs[1:-1].strip())
        return [c.replace("''", "'") for c in cells]
    m = _ZEROS.match(rhs)
    if m:
        dims = _dims(m.group(1), where, line, "zeros")
        if len(dims) not in (2, 3):
            raise SpaceDynParseError(f"{where}:{line}: zeros takes 2 or 3 sizes here: {rhs!r}")
        return np.zeros(dims)
    if field == "mass" and re.fullmatch(rf"{var}\.m0\s*\+\s*sum\(\s*{var}\.m\s*\)", rhs):
        if "m0" not in values or "m" not in values:
            raise SpaceDynParseError(f"{where}:{line}: {var}.mass before {var}.m0 and {var}.m")
        return float(np.asarray(values["m0"]).reshape(-1)[0]) + float(np.sum(values["m"]))
    if _NUMBER.match(rhs):
        return float(rhs)
    raise SpaceDynParseError(f"{where}:{line}: value not understood: {rhs!r}")


def _assign_indexed(values, field, index_text, value, where, line):
    if field not in values or not isinstance(values[field], np.ndarray):
        raise SpaceDynParseError(f"{where}:{line}: {field}(...) assigned before {field} is an array")
    target = values[field]
    parts = [p.strip() for p in index_text.split(",")]
    if len(parts) != target.ndim:
        raise SpaceDynParseError(f"{where}:{line}: {len(parts)} indices into {field} of shape {target.shape}")
    index = []
    for k, p in enumerate(parts):
        if p == ":":
            index.append(slice(None))
        elif re.fullmatch(r"\d+", p) and 1 <= int(p) <= target.shape[k]:
            index.append(int(p) - 1)
        else:
            raise SpaceDynParseError(f"{where}:{line}: index {p!r} out of range for {field} of shape {target.shape}")
    if isinstance(value, str):
        raise SpaceDynParseError(f"{where}:{line}: a string assigned into {field}({index_text})")
    if not isinstance(value, np.ndarray):
        value = np.array([[value]])
    view = target[tuple(index)]
    if value.shape == np.shape(view):
        target[tuple(index)] = value
    elif np.ndim(view) <= 1 and value.size == np.size(view) and sum(d > 1 for d in value.shape) <= 1:
        target[tuple(index)] = value.reshape(np.shape(view))
    else:
        raise SpaceDynParseError(f"{where}:{line}: a {value.shape[0]}x{value.shape[1]} value for "
                                 f"{field}({index_text}) of shape {np.shape(view)}")


def parse_m_file(path):
    """The fields of a SpaceDyn LP or SV function file as a dict: a [ ] literal is a 2-D float
    array as MATLAB shapes it ([1 2 3] is 1x3, [1; 2; 3] is 3x1), zeros(a,b[,c]) an array of that
    shape, a bare number a float, a '...' string a str. The dict's '__var__' is the function's
    output name ('LP' or 'SV') and '__name__' the function's name. Raises SpaceDynParseError
    (naming the file and line) on anything outside the subset."""
    where = os.fspath(path)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    values, var, ended = {}, None, False
    for line, st in _statements(text, where):
        if ended:
            raise SpaceDynParseError(f"{where}:{line}: statement after 'end': {st!r}")
        if var is None:
            m = _FUNCTION.match(st)
            if not m:
                raise SpaceDynParseError(f"{where}:{line}: expected 'function LP = name()' first, got {st!r}")
            var = m.group(1)
            values["__var__"], values["__name__"] = var, m.group(2)
            continue
        if st in ("end", "end;"):
            ended = True
            continue
        m = _ASSIGN.match(st)
        if not m or m.group(1) != var:
            raise SpaceDynParseError(f"{where}:{line}: statement not understood: {st!r}")
        field, index_text, rhs = m.group(2), m.group(3), m.group(4)
        value = _value(rhs, var, field, values, where, line)
        if index_text is None:
            if field in values:
                raise SpaceDynParseError(f"{where}:{line}: {var}.{field} assigned twice")
            values[field] = value
        else:
            _assign_indexed(values, field, index_text, value, where, line)
    if var is None:
        raise SpaceDynParseError(f"{where}: no 'function' line")
    return values


# ----------------------------------------------------------------------------------------------
# reading the fields

def _load(x):
    return parse_m_file(x) if isinstance(x, (str, os.PathLike)) else x


def _vector(d, key, n, default=None):
    if key not in d:
        if default is None:
            raise KeyError(f"{key} is missing")
        return np.full(n, float(default))
    v = np.asarray(d[key], dtype=float)
    if v.size != n or (v.ndim >= 2 and sorted(v.shape)[-2] > 1):
        raise ValueError(f"{key}: expected a vector of {n}, got shape {v.shape}")
    return v.reshape(n)


def _matrix3n(d, key, n):
    v = np.asarray(d[key], dtype=float)
    if v.size != 3 * n or v.ndim < 2 or v.shape[0] != 3:
        raise ValueError(f"{key}: expected 3x{n}, got shape {v.shape}")
    return v.reshape(3, n)


def num_q(LP):
    n = float(np.asarray(LP["num_q"]).reshape(-1)[0])
    if n != int(n) or n < 0:
        raise ValueError(f"num_q = {n}")
    return int(n)


def _topology(LP):
    n = num_q(LP)
    BB = _vector(LP, "BB", n)
    if np.any(BB != np.round(BB)):
        raise ValueError(f"BB not integers: {BB}")
    BB = BB.astype(int)
    for i in range(1, n + 1):
        if not 0 <= BB[i - 1] < i:
            raise ValueError(f"BB({i}) = {BB[i - 1]}: a parent must have a smaller index")
    jt = LP.get("J_type", "")
    if not isinstance(jt, str) or len(jt) != n or set(jt) - {"R", "P"}:
        raise ValueError(f"J_type {jt!r}: expected {n} characters of 'R'/'P'")
    return n, BB, jt


def connectivity(LP):
    """(S0, SS) as SpaceDyn defines them from BB: S0(i) = 1 if BB(i) = 0; SS(i,j) = 1 if
    BB(j) = i, SS(i,i) = -1, else 0. For comparing with the file's LP.S0, LP.SS."""
    n, BB, _ = _topology(LP)
    S0 = (BB == 0).astype(float)
    SS = -np.eye(n)
    for j in range(1, n + 1):
        if BB[j - 1]:
            SS[BB[j - 1] - 1, j - 1] = 1.0
    return S0, SS


def chain(LP, i):
    """SpaceDyn's j_num for link i (1-based): the joints from the base to link i, base side first."""
    _, BB, _ = _topology(LP)
    out = [i]
    while BB[out[0] - 1]:
        out.insert(0, int(BB[out[0] - 1]))
    return out


def _base_state(SV):
    R0 = _vector(SV, "R0", 3)
    if "A0" in SV:
        A0 = np.asarray(SV["A0"], dtype=float)
        if A0.shape != (3, 3):
            raise ValueError(f"A0: expected 3x3, got {A0.shape}")
    else:
        A0 = rpy2dc(_vector(SV, "Q0", 3)).T
    return R0, A0


def total_mass(LP):
    """m0 + sum(m)."""
    LP = _load(LP)
    n = num_q(LP)
    return float(np.asarray(LP["m0"]).reshape(-1)[0]) + float(np.sum(_vector(LP, "m", n)))


def kinematics(LP, SV):
    """(AA, RR, joint_positions, joint_axes): AA the list of the n links' 3x3 orientations
    (link frame -> inertial, calc_aa), RR the 3xn centroids (calc_pos), the 3xn points the joint
    axes pass through (for 'P' the point fixed in the parent) and the 3xn unit axes A_i Ez, all
    inertial. n = 0: [], and 3x0 arrays."""
    LP, SV = _load(LP), _load(SV)
    n, BB, jt = _topology(LP)
    R0, A0 = _base_state(SV)
    q = _vector(SV, "q", n, 0.0)
    AA, RR = [], np.zeros((3, n))
    if n:
        Qi = _matrix3n(LP, "Qi", n)
        c0 = _matrix3n(LP, "c0", n)
        cc = np.asarray(LP["cc"], dtype=float)
        if cc.size != 3 * n * n or cc.shape[0] != 3:
            raise ValueError(f"cc: expected 3x{n}x{n}, got shape {cc.shape}")
        cc = cc.reshape(3, n, n)
    JP, JA = np.zeros((3, n)), np.zeros((3, n))
    for i in range(1, n + 1):
        p = BB[i - 1]
        A_p = A0 if p == 0 else AA[p - 1]
        if jt[i - 1] == "R":
            A_i = A_p @ rpy2dc(Qi[0, i - 1], Qi[1, i - 1], Qi[2, i - 1] + q[i - 1]).T
        else:
            A_i = A_p @ rpy2dc(Qi[:, i - 1]).T
        AA.append(A_i)
        joint = R0 + A0 @ c0[:, i - 1] if p == 0 else RR[:, p - 1] + A_p @ cc[:, p - 1, i - 1]
        slide = EZ * q[i - 1] if jt[i - 1] == "P" else np.zeros(3)
        RR[:, i - 1] = joint + A_i @ (slide - cc[:, i - 1, i - 1])
        JP[:, i - 1] = joint
        JA[:, i - 1] = A_i @ EZ
    return AA, RR, JP, JA


def _point_jacobian(jt, RR0, JP, JA, links, point, n):
    """(J_T, J_R), 3x(6+n), of a point fixed in the last link of `links` (the chain)."""
    JT = np.zeros((3, 6 + n))
    JR = np.zeros((3, 6 + n))
    JT[:, :3] = np.eye(3)
    JT[:, 3:6] = -tilde(point - RR0)
    JR[:, 3:6] = np.eye(3)
    for j in links:
        if jt[j - 1] == "R":
            JT[:, 5 + j] = np.cross(JA[:, j - 1], point - JP[:, j - 1])
            JR[:, 5 + j] = JA[:, j - 1]
        else:
            JT[:, 5 + j] = JA[:, j - 1]
    return JT, JR


def link_jacobians(LP, SV):
    """[(J_T, J_R)] for the base then links 1..n, each 3x(6+n): the centroid's inertial velocity
    and the body's inertial angular velocity as linear maps of (v0, w0, qd)."""
    LP, SV = _load(LP), _load(SV)
    n, _, jt = _topology(LP)
    R0, _ = _base_state(SV)
    _, RR, JP, JA = kinematics(LP, SV)
    base_T = np.zeros((3, 6 + n))
    base_T[:, :3] = np.eye(3)
    base_R = np.zeros((3, 6 + n))
    base_R[:, 3:6] = np.eye(3)
    out = [(base_T, base_R)]
    for i in range(1, n + 1):
        out.append(_point_jacobian(jt, R0, JP, JA, chain(LP, i), RR[:, i - 1], n))
    return out


def _inertias(LP, n):
    I0 = np.asarray(LP["inertia0"], dtype=float)
    if I0.shape != (3, 3):
        raise ValueError(f"inertia0: expected 3x3, got {I0.shape}")
    I = np.asarray(LP["inertia"], dtype=float)
    if I.size != 9 * n or (n and I.shape != (3, 3 * n)):
        raise ValueError(f"inertia: expected 3x{3 * n}, got shape {I.shape}")
    I = I.reshape(3, 3 * n)
    return I0, [I[:, 3 * i:3 * i + 3] for i in range(n)]


def system_inertia(LP, SV):
    """HH, (6+n)x(6+n), in (v0, w0, qd): sum over the base and the links of
    m J_T' J_T + J_R' (A I A') J_R."""
    LP, SV = _load(LP), _load(SV)
    n = num_q(LP)
    _, A0 = _base_state(SV)
    AA, _, _, _ = kinematics(LP, SV)
    I0, Is = _inertias(LP, n)
    masses = [float(np.asarray(LP["m0"]).reshape(-1)[0])] + list(_vector(LP, "m", n))
    rotations = [A0] + AA
    inertias = [I0] + Is
    HH = np.zeros((6 + n, 6 + n))
    for (JT, JR), m, A, I in zip(link_jacobians(LP, SV), masses, rotations, inertias):
        HH += m * JT.T @ JT + JR.T @ (A @ I @ A.T) @ JR
    return HH


def generalized_inertia(LP, SV):
    """H* = H_m - H_bm' H_b^-1 H_bm (n x n; 0x0 when n = 0)."""
    HH = system_inertia(LP, SV)
    Hb, Hbm, Hm = HH[:6, :6], HH[:6, 6:], HH[6:, 6:]
    return Hm - Hbm.T @ np.linalg.solve(Hb, Hbm)


def _end_links(LP):
    n = num_q(LP)
    SE = _vector(LP, "SE", n)
    if set(SE) - {0.0, 1.0}:
        raise ValueError(f"SE: expected 0/1 entries, got {SE}")
    return [i for i in range(1, n + 1) if SE[i - 1] == 1]


def end_points(LP, SV):
    """[(position (3,), orientation 3x3)] of the end points in SE order (f_kin_e):
    RR_i + A_i ce(:,i) and A_i rpy2dc(Qe(:,i))'."""
    LP, SV = _load(LP), _load(SV)
    n = num_q(LP)
    links = _end_links(LP)
    if not links:
        return []
    ce, Qe = _matrix3n(LP, "ce", n), _matrix3n(LP, "Qe", n)
    AA, RR, _, _ = kinematics(LP, SV)
    return [(RR[:, i - 1] + AA[i - 1] @ ce[:, i - 1], AA[i - 1] @ rpy2dc(Qe[:, i - 1]).T) for i in links]


def end_point_jacobian(LP, SV, k):
    """6x(6+n): the twist (v; w) of end point k (1-based, SpaceDyn's num_e), v of the point itself,
    as a linear map of (v0, w0, qd)."""
    LP, SV = _load(LP), _load(SV)
    n, _, jt = _topology(LP)
    links = _end_links(LP)
    if not 1 <= k <= len(links):
        raise IndexError(f"end point {k}: the model has {len(links)} (numbered from 1)")
    R0, _ = _base_state(SV)
    _, _, JP, JA = kinematics(LP, SV)
    pe = end_points(LP, SV)[k - 1][0]
    JT, JR = _point_jacobian(jt, R0, JP, JA, chain(LP, links[k - 1]), pe, n)
    return np.vstack([JT, JR])


def generalized_jacobian(LP, SV, k):
    """J* (6xn) of end point k (1-based, as SpaceDyn's calc_gj num_e): J_m - J_b H_b^-1 H_bm."""
    J = end_point_jacobian(LP, SV, k)
    HH = system_inertia(LP, SV)
    return J[:, 6:] - J[:, :6] @ np.linalg.solve(HH[:6, :6], HH[:6, 6:])
