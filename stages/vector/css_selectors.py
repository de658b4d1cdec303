"""CSS selectors (Selectors Level 4, the static part) over an SVG file's ElementTree, with their specificity.

Supported: type, universal, ``#id``, ``.class`` and attribute selectors, the descendant,
child (``>``), next-sibling (``+``) and subsequent-sibling (``~``) combinators, lists, and
the structural pseudo-classes (``:root``, ``:empty``, ``:first-child``, ``:nth-child()``
and kin, ``:not()``, ``:is()``, ``:where()``). User-action and link pseudo-classes
(``:hover``...) and pseudo-elements never match: nobody hovers over a rendered frame and
SVG elements have no ``::before``. Anything else raises :class:`UnsupportedCss`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable
from xml.etree import ElementTree

from tinycss2.nth import parse_nth

from fluidymation.stages.vector.css_syntax import InvalidCss, UnsupportedCss, text_of
from fluidymation.stages.vector.safety import local_name

Specificity = tuple[int, int, int]
_NEVER_MATCHING = {"hover", "active", "focus", "focus-visible", "focus-within", "visited", "link", "any-link",
                   "target", "target-within", "local-link", "checked", "indeterminate", "default", "disabled",
                   "enabled", "invalid", "valid", "user-invalid", "user-valid", "placeholder-shown", "autofill",
                   "playing", "paused", "fullscreen", "modal", "picture-in-picture", "popover-open"}


class DocumentIndex:
    """Parents and sibling positions of an ElementTree, for matching combinators and structural pseudo-classes."""

    def __init__(self, root: ElementTree.Element):
        self.root = root
        self._parents: dict[int, ElementTree.Element] = {}
        for parent in root.iter():
            for child in parent:
                self._parents[id(child)] = parent

    def parent(self, element: ElementTree.Element) -> ElementTree.Element | None:
        return self._parents.get(id(element))

    def siblings(self, element: ElementTree.Element) -> list[ElementTree.Element]:
        parent = self.parent(element)
        return [element] if parent is None else list(parent)


Test = Callable[[ElementTree.Element, DocumentIndex], bool]


@dataclass
class _Compound:
    """The simple selectors of one compound: every test must hold."""

    tests: list[Test] = field(default_factory=list)
    specificity: list[int] = field(default_factory=lambda: [0, 0, 0])

    def matches(self, element, index) -> bool:
        return all(test(element, index) for test in self.tests)


@dataclass(frozen=True)
class Selector:
    """A complex selector: compounds joined by combinators, matched right to left."""

    compounds: tuple[_Compound, ...]
    combinators: tuple[str, ...]
    specificity: Specificity
    text: str

    def matches(self, element: ElementTree.Element, index: DocumentIndex) -> bool:
        return self._matches_from(len(self.compounds) - 1, element, index)

    def _matches_from(self, position: int, element, index) -> bool:
        if not self.compounds[position].matches(element, index):
            return False
        if position == 0:
            return True
        combinator = self.combinators[position - 1]
        if combinator in (">", " "):
            parent = index.parent(element)
            while parent is not None:
                if self._matches_from(position - 1, parent, index):
                    return True
                if combinator == ">":
                    return False
                parent = index.parent(parent)
            return False
        siblings = index.siblings(element)
        earlier = siblings[:siblings.index(element)]
        candidates = earlier[-1:] if combinator == "+" else reversed(earlier)
        return any(self._matches_from(position - 1, sibling, index) for sibling in candidates)


def parse_selector_list(prelude) -> list[Selector]:
    """The selectors of a rule's prelude; raises InvalidCss or UnsupportedCss for the whole list, as browsers drop a
    rule whose selector list holds one they do not understand."""
    return [_complex(group) for group in _split_top_level_commas(prelude)]


def _split_top_level_commas(prelude) -> list[list]:
    groups: list[list] = [[]]
    for value in prelude:
        if value.type == "literal" and value.value == ",":
            groups.append([])
        elif value.type != "comment":
            groups[-1].append(value)
    groups = [_trimmed(group) for group in groups]
    if any(not group for group in groups):
        raise InvalidCss(f"'{text_of(prelude)}' has an empty selector")
    return groups


def _trimmed(values: list) -> list:
    start, end = 0, len(values)
    while start < end and values[start].type == "whitespace":
        start += 1
    while end > start and values[end - 1].type == "whitespace":
        end -= 1
    return values[start:end]


def _complex(values: list) -> Selector:
    compounds: list[_Compound] = [_Compound()]
    combinators: list[str] = []
    pending: str | None = None
    empty = True
    position = 0
    while position < len(values):
        value = values[position]
        if value.type == "whitespace":
            pending = pending or " "
            position += 1
        elif value.type == "literal" and value.value in (">", "+", "~"):
            if empty or pending not in (None, " "):
                raise InvalidCss(f"'{text_of(values)}' has a misplaced combinator")
            pending = value.value
            position += 1
        else:
            if pending is not None:
                combinators.append(pending)
                compounds.append(_Compound())
                pending = None
            position = _simple(values, position, compounds[-1])
            empty = False
    if pending is not None:
        raise InvalidCss(f"'{text_of(values)}' ends with a combinator")
    specificity = tuple(sum(compound.specificity[i] for compound in compounds) for i in range(3))
    return Selector(tuple(compounds), tuple(combinators), specificity, text_of(values))


def _simple(values: list, position: int, compound: _Compound) -> int:
    """Parse the simple selector at ``position`` into ``compound``; the position after it."""
    value = values[position]
    following = values[position + 1] if position + 1 < len(values) else None
    if following is not None and following.type == "literal" and following.value == "|":
        raise UnsupportedCss(f"the namespace selector in '{text_of(values)}' is not matched")
    if value.type == "ident":
        name = value.value
        compound.tests.append(lambda element, index: local_name(element.tag) == name)
        compound.specificity[2] += 1
        return position + 1
    if value.type == "literal" and value.value == "*":
        return position + 1
    if value.type == "hash" and value.is_identifier:
        wanted = value.value
        compound.tests.append(lambda element, index: element.get("id") == wanted)
        compound.specificity[0] += 1
        return position + 1
    if value.type == "literal" and value.value == "." and following is not None and following.type == "ident":
        wanted = following.value
        compound.tests.append(lambda element, index: wanted in (element.get("class") or "").split())
        compound.specificity[1] += 1
        return position + 2
    if value.type == "[] block":
        compound.tests.append(_attribute(value))
        compound.specificity[1] += 1
        return position + 1
    if value.type == "literal" and value.value == ":" and following is not None:
        if following.type == "literal" and following.value == ":":
            compound.tests.append(lambda element, index: False)
            compound.specificity[2] += 1
            return position + 3
        _pseudo_class(following, compound, values)
        return position + 2
    raise InvalidCss(f"'{text_of(values)}' is not a selector")


def _attribute(block) -> Test:
    parts = [value for value in block.content if value.type not in ("whitespace", "comment")]
    if not parts or parts[0].type != "ident":
        raise InvalidCss(f"'[{text_of(block.content)}]' is not an attribute selector")
    name = parts[0].value
    if len(parts) == 1:
        return lambda element, index: _attribute_value(element, name) is not None
    if len(parts) not in (3, 4) or parts[1].type != "literal" or not parts[1].value.endswith("=") or \
            parts[2].type not in ("ident", "string") or (len(parts) == 4 and parts[3].type != "ident"):
        raise InvalidCss(f"'[{text_of(block.content)}]' is not an attribute selector")
    operator, wanted = parts[1].value[:-1], parts[2].value
    flag = parts[3].lower_value if len(parts) == 4 else "s"
    fold = (lambda text: text.lower()) if flag == "i" else (lambda text: text)
    compare = {"": lambda actual: actual == fold(wanted),
               "~": lambda actual: fold(wanted) in actual.split(),
               "|": lambda actual: actual == fold(wanted) or actual.startswith(fold(wanted) + "-"),
               "^": lambda actual: bool(wanted) and actual.startswith(fold(wanted)),
               "$": lambda actual: bool(wanted) and actual.endswith(fold(wanted)),
               "*": lambda actual: bool(wanted) and fold(wanted) in actual}.get(operator)
    if compare is None:
        raise InvalidCss(f"'[{text_of(block.content)}]' has an unknown operator")

    def test(element, index):
        actual = _attribute_value(element, name)
        return actual is not None and compare(fold(actual))

    return test


def _attribute_value(element, name: str) -> str | None:
    for key, value in element.attrib.items():
        if local_name(key) == name:
            return value
    return None


def _pseudo_class(value, compound: _Compound, values) -> None:
    """Add the pseudo-class ``value`` (an ident or a function) to ``compound``."""
    if value.type == "ident":
        name = value.lower_value
        if name in _NEVER_MATCHING:
            compound.tests.append(lambda element, index: False)
        elif name in _STRUCTURAL:
            compound.tests.append(_STRUCTURAL[name])
        else:
            raise UnsupportedCss(f"the pseudo-class ':{name}' in '{text_of(values)}' is not matched")
        compound.specificity[1] += 1
        return
    if value.type != "function":
        raise InvalidCss(f"'{text_of(values)}' is not a selector")
    name = value.lower_name
    if name in ("not", "is", "where"):
        inner = parse_selector_list(value.arguments)
        if name == "not":
            compound.tests.append(lambda element, index: not any(s.matches(element, index) for s in inner))
        else:
            compound.tests.append(lambda element, index: any(s.matches(element, index) for s in inner))
        if name != "where":
            best = max(selector.specificity for selector in inner)
            compound.specificity[:] = [a + b for a, b in zip(compound.specificity, best)]
        return
    if name in ("nth-child", "nth-last-child", "nth-of-type", "nth-last-of-type"):
        if any(argument.type == "ident" and argument.lower_value == "of" for argument in value.arguments):
            raise UnsupportedCss(f"':{name}(… of S)' in '{text_of(values)}' is not matched")
        parsed = parse_nth(value.arguments)
        if parsed is None:
            raise InvalidCss(f"':{name}({text_of(value.arguments)})' is not an An+B expression")
        compound.tests.append(_nth(*parsed, last=name.startswith("nth-last"), of_type=name.endswith("of-type")))
        compound.specificity[1] += 1
        return
    raise UnsupportedCss(f"the pseudo-class ':{name}()' in '{text_of(values)}' is not matched")


def _nth(a: int, b: int, *, last: bool, of_type: bool) -> Test:
    """Whether the element is the (a·n + b)-th of its siblings (of its type), counting from the end if ``last``."""

    def test(element, index):
        siblings = index.siblings(element)
        if of_type:
            siblings = [sibling for sibling in siblings if sibling.tag == element.tag]
        position = (len(siblings) - siblings.index(element)) if last else siblings.index(element) + 1
        if a == 0:
            return position == b
        return (position - b) % a == 0 and (position - b) // a >= 0

    return test


_STRUCTURAL: dict[str, Test] = {
    "root": lambda element, index: element is index.root,
    "empty": lambda element, index: len(element) == 0 and not element.text,
    "first-child": _nth(0, 1, last=False, of_type=False),
    "last-child": _nth(0, 1, last=True, of_type=False),
    "only-child": lambda element, index: len(index.siblings(element)) == 1,
    "first-of-type": _nth(0, 1, last=False, of_type=True),
    "last-of-type": _nth(0, 1, last=True, of_type=True),
    "only-of-type": lambda element, index: sum(s.tag == element.tag for s in index.siblings(element)) == 1,
}
