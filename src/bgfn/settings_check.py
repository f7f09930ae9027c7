"""A profile checked against :mod:`bgfn.settings`: :func:`complete` lays a merged profile over the defaults (as a
``base:`` chain merges: sections key by key) and checks it against :class:`bgfn.settings.Profile`, raising
:class:`ProfileError` with the dotted key, what was expected and the value (a misspelt key: the closest valid one).
"""

from __future__ import annotations

import copy
import difflib
import json
import math
from typing import Any, get_args, get_origin

from pydantic import BaseModel, ValidationError

from bgfn.settings import DEFAULT_DATASET_KEY, REQUIRED, Data, DriveParams, OutageRule, Profile, defaults, defaults_of


class ProfileError(ValueError):
    """A profile value that breaks the schema: ``path`` (dotted key), what was ``expected``, what was ``found``."""

    def __init__(self, path: str, expected: str, found: str):
        super().__init__(f"{path}: expected {expected}, found {found}")
        self.path, self.expected, self.found = path, expected, found


def fmt(v: Any) -> str:
    """A value as a message shows it."""
    return repr(v) if not isinstance(v, float) else f"{v:g}"


def _path(loc) -> str:
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def _model_at(model: type[BaseModel], keys) -> type[BaseModel] | None:
    """The model of the section at ``keys`` (a mapping of named sections, such as ``variants``, passed through)."""
    keys = list(keys)
    while keys:
        key = keys.pop(0)
        field = next((f for n, f in model.model_fields.items() if (f.alias or n) == key), None)
        sub = field.annotation if field else None
        if get_origin(sub) is dict and keys:
            sub = get_args(sub)[1]
            keys.pop(0)
        if not (isinstance(sub, type) and issubclass(sub, BaseModel)):
            return None
        model = sub
    return model


_EXPECT = {"int_type": "an integer", "float_type": "a number", "bool_type": "true or false",
           "string_type": "a string", "list_type": "a list", "dict_type": "a mapping", "model_type": "a mapping of keys",
           "finite_number": "a finite number", "missing": "a value"}
_BOUND = {"greater_than": ">", "greater_than_equal": ">=", "less_than": "<", "less_than_equal": "<="}


def _error(model: type[BaseModel], err: dict, prefix: str) -> ProfileError:
    loc, kind, ctx = err["loc"], err["type"], err.get("ctx") or {}
    path = (prefix + "." if prefix and loc else prefix) + _path(loc)
    found = "missing" if kind == "missing" else ("unknown key" if kind == "extra_forbidden" else
                                                  fmt(err.get("input")))
    if kind == "extra_forbidden":
        owner = _model_at(model, loc[:-1]) or model
        keys = [f.alias or n for n, f in owner.model_fields.items()]
        close = difflib.get_close_matches(str(loc[-1]), keys, n=1, cutoff=0.6)
        where = path.rsplit(".", 1)[0] + "." if "." in path else ""
        hint = f" (did you mean {where}{close[0]}?)" if close else ""
        return ProfileError(path, f"one of the keys {', '.join(sorted(keys))}{hint}", found)
    if kind in _BOUND:
        bound = next(iter(ctx.values()))
        return ProfileError(path, f"a number {_BOUND[kind]} {bound:,}" if isinstance(bound, int) else
                            f"a number {_BOUND[kind]} {bound:g}", found)
    if kind == "literal_error":
        return ProfileError(path, f"one of {str(ctx.get('expected')).replace(' or ', ', ')}", found)
    if kind in ("too_short", "too_long"):
        field = (_model_at(model, loc[:-1]) or model).model_fields.get(str(loc[-1]))
        lengths = [getattr(m, k, None) for m in (field.metadata if field else []) for k in ("min_length", "max_length")]
        if lengths.count(None) == len(lengths) - 2 and len(set(lengths) - {None}) == 1:   # a vector (N, E, D)
            return ProfileError(path, f"a list of exactly {max(n for n in lengths if n)} numbers", found)
        n = ctx.get("min_length") if kind == "too_short" else ctx.get("max_length")
        return ProfileError(path, f"a list of {'at least' if kind == 'too_short' else 'at most'} {n} item(s)", found)
    return ProfileError(path, _EXPECT.get(kind, err.get("msg", "a valid value")), found)


def check_model(model: type[BaseModel], value: Any, prefix: str = "") -> None:
    """Raise :class:`ProfileError` where ``value`` breaks ``model`` (``prefix``: its dotted key)."""
    if not isinstance(value, dict):
        raise ProfileError(prefix, "a mapping of keys", type(value).__name__)
    try:
        model.model_validate(value)
    except ValidationError as exc:
        raise _error(model, exc.errors()[0], prefix) from None


def _number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _check_windows_entry(path: str, entry) -> None:
    if isinstance(entry, dict):
        if "rule" not in entry:
            raise ProfileError(f"{path}.rule", "the name of the rule that picks the windows", "missing")
        check_model(OutageRule, entry, path)
        return
    if not isinstance(entry, list) or not entry:
        raise ProfileError(path, "a list of [start, duration] (s) of at least 1 item, or a rule", fmt(entry))
    for i, item in enumerate(entry):
        if not (isinstance(item, list) and len(item) == 2 and all(_number(v) for v in item)):
            raise ProfileError(f"{path}[{i}]", "[start, duration] in s", fmt(item))


def _check_free(cfg: dict) -> None:
    """The keys whose value takes one of several forms."""
    spec = cfg["outage_windows"]
    if isinstance(spec, dict):
        for key, entry in spec.items():
            _check_windows_entry(f"outage_windows.{key}", entry)
    else:
        _check_windows_entry("outage_windows", spec)
    ns = cfg["nav"]["noise_scale"]
    if isinstance(ns, dict) and DEFAULT_DATASET_KEY not in ns:
        raise ProfileError("nav.noise_scale", f"a '{DEFAULT_DATASET_KEY}' entry beside the per-dataset ones", fmt(ns))
    for key, value in (ns.items() if isinstance(ns, dict) else [(None, ns)]):
        if value != "auto" and not (_number(value) and value > 0):
            raise ProfileError("nav.noise_scale" + (f".{key}" if key else ""),
                               "a positive number or 'auto' (or per dataset, with a 'default')", fmt(value))
    vp = cfg["train"]["val_position"]
    if not (vp in ("start", "middle", "end") or (_number(vp) and 0 <= vp <= 1)):
        raise ProfileError("train.val_position", "'start', 'middle', 'end' or a fraction in [0, 1]", fmt(vp))
    seeds = cfg["evaluate"]["odometer"]["network_seeds"]
    if isinstance(seeds, dict) and DEFAULT_DATASET_KEY not in seeds:
        raise ProfileError("evaluate.odometer.network_seeds", f"a '{DEFAULT_DATASET_KEY}' list beside the per-dataset "
                           "ones", fmt(seeds))
    for key, value in (seeds.items() if isinstance(seeds, dict) else [(None, seeds)]):
        if not (isinstance(value, list) and value and all(isinstance(s, int) and not isinstance(s, bool) and s >= 0
                                                          for s in value)):
            raise ProfileError("evaluate.odometer.network_seeds" + (f".{key}" if key else ""),
                               "a list of non-negative integers of at least 1 item (or per drive, with a 'default')",
                               fmt(value))
    inputs = cfg["evaluate"]["odometer"]["inputs"]
    if isinstance(inputs, dict):
        if DEFAULT_DATASET_KEY not in inputs:
            raise ProfileError("evaluate.odometer.inputs", f"a '{DEFAULT_DATASET_KEY}' choice beside the per-network "
                               "ones", fmt(inputs))
        unknown = sorted(set(inputs) - {DEFAULT_DATASET_KEY, *cfg["evaluate"]["odometer"]["methods"]})
        if unknown:
            raise ProfileError("evaluate.odometer.inputs." + unknown[0], "a network of evaluate.odometer.methods "
                               f"({', '.join(cfg['evaluate']['odometer']['methods'])}) or '{DEFAULT_DATASET_KEY}'",
                               fmt(unknown[0]))
    std = cfg["evaluate"]["pseudo_gps"]["std_m"]
    if std is not None and not (_number(std) and std > 0):
        raise ProfileError("evaluate.pseudo_gps.std_m", "a positive number, m, or null", fmt(std))
    data = cfg["data"]
    for key, value in data.items():
        if key in Data.model_fields:
            continue
        if not isinstance(value, dict):
            close = difflib.get_close_matches(str(key), list(Data.model_fields), n=1, cutoff=0.6)
            hint = f" (did you mean data.{close[0]}?)" if close else ""
            raise ProfileError(f"data.{key}", f"one of the keys {', '.join(sorted(Data.model_fields))} or a drive's "
                               f"parameters (a mapping){hint}", fmt(value))
        check_model(DriveParams, value, f"data.{key}")   # which keys a drive takes: the edge's check


def merge(base: dict, override: dict) -> dict:
    """``override`` laid over ``base``: mappings merge key by key; any other value, lists included, replaces."""
    out = copy.deepcopy(base)
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def _fill_rules(cfg: dict) -> None:
    """Each outage rule with its left-out keys set to :class:`OutageRule`'s defaults."""
    spec = cfg.get("outage_windows")
    if isinstance(spec, dict):
        for key, entry in spec.items():
            if isinstance(entry, dict) and "rule" in entry:
                spec[key] = {"rule": entry["rule"], **defaults_of(OutageRule), **entry}


def complete(cfg: dict) -> dict:
    """The merged profile ``cfg`` laid over :func:`defaults` and checked against :class:`Profile`: every key with its
    value (the defaults' where ``cfg`` leaves one out), as plain data in the YAML's own types.

    Raises
    ------
    ProfileError
        The first key that breaks the schema: its dotted path, what was expected, the value (an unknown key: the
        closest valid one).
    """
    for key in REQUIRED:
        if key not in cfg:
            raise ProfileError(key, f"required top-level keys {', '.join(REQUIRED)}", "missing")
    base = defaults()
    own = {k: v for k, v in cfg.items() if not (v is None and isinstance(base.get(k), dict))}   # a comments-only section
    out = merge(base, own)
    order = [k for k in Profile.model_fields if k in out]         # the keys in the order of the file's sections
    out = {k: out[k] for k in order + [k for k in out if k not in order]}
    _fill_rules(out)
    check_model(Profile, out)
    _check_free(out)
    return out


def listing(model: type[BaseModel] = Profile, indent: str = "") -> list[str]:
    """Every key of ``model`` as YAML lines: its default and, as a comment, its description."""
    out = []
    for name, field in model.model_fields.items():
        key, sub = field.alias or name, field.annotation
        if isinstance(sub, type) and issubclass(sub, BaseModel):
            out += [f"{indent}{key}:{'':<{max(1, 40 - len(indent) - len(key))}}# {field.description}",
                    *listing(sub, indent + "  ")]
            continue
        value = "(required)" if field.is_required() else json.dumps(field.get_default(call_default_factory=True))
        out.append(f"{indent}{key}: {value}  # {field.description}")
    return out


if __name__ == "__main__":   # python -m bgfn.settings_check: every key, its default and its meaning
    print("\n".join(listing()))
