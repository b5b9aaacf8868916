"""Signed alias classes (union-find): properties any correct merge must have."""

from hypothesis import given, settings
from hypothesis import strategies as st

from bgmodelica.structure.alias import alias_classes


@st.composite
def linked(draw):
    n = draw(st.integers(1, 25))
    links = draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1),
                                    st.sampled_from([1.0, -1.0])), max_size=40))
    rank = draw(st.lists(st.integers(0, 3), min_size=n, max_size=n))
    return n, links, rank


def _classes(n, links):
    """Connected components of the link graph, by a plain graph search."""
    nbrs = {v: set() for v in range(n)}
    for a, b, _ in links:
        nbrs[a].add(b)
        nbrs[b].add(a)
    label, out = {}, []
    for v in range(n):
        if v in label:
            continue
        label[v] = len(out)
        todo, comp = [v], [v]
        while todo:
            for w in nbrs[todo.pop()]:
                if w not in label:
                    label[w] = label[v]
                    todo.append(w)
                    comp.append(w)
        out.append(comp)
    return out


@settings(max_examples=300, deadline=None)
@given(linked())
def test_alias_classes_satisfy_the_links_they_used(case):
    n, links, rank = case
    cls = alias_classes(n, links, rank)
    comps = _classes(n, links)
    for comp in comps:                       # one representative per connected class
        reps = {cls.rep[v] for v in comp}
        assert len(reps) == 1
        (r,) = reps
        assert r in comp and cls.sign[r] == 1.0
        assert rank[r] == max(rank[v] for v in comp)
    # every merge used one link: the rest closed cycles and are reported redundant
    assert len(links) - len(cls.redundant) == n - len(comps)
    redundant = set(cls.redundant)
    value = [0.0] * n                        # representatives get arbitrary values
    for v in range(n):
        if cls.rep[v] == v:
            value[v] = 1.0 + v
    x = [cls.sign[v] * value[cls.rep[v]] for v in range(n)]
    for k, (a, b, s) in enumerate(links):
        if k not in redundant:
            assert x[a] == s * x[b]
        else:                                # a cycle: both ends already one class
            assert cls.rep[a] == cls.rep[b]


def test_alias_tie_goes_to_the_second_class():
    cls = alias_classes(3, [(0, 1, 1.0), (2, 1, -1.0)], [0, 0, 0])
    assert cls.rep == [1, 1, 1]
    assert cls.sign == [1.0, 1.0, -1.0]
    assert alias_classes(2, [(0, 1, -1.0)], [1, 0]).rep == [0, 0]
