"""Every symbol of f's formula is said in words after it: what f = F / (E* h L) is can be read
from the line under a run's table, curve.csv's header and plot.png's axis alone."""

from __future__ import annotations

import re

import pytest

from frictionlab.plugin import ForceNormalisation
from frictionlab.plugin.registry import default_registry


def symbols_of(formula: str) -> list[str]:
    """The symbols of ``F / (E* h L)``: F, E*, h, L."""
    return [s for s in re.split(r"[\s/()]+", formula) if s]


def explained(definition: str) -> list[str]:
    """The symbols a definition says in words: each part after the formula starts with one."""
    return [part.split(" ", 1)[0] for part in definition.split(", ")[1:]]


def built_in_normalisations() -> list[tuple[str, int, ForceNormalisation]]:
    registry = default_registry()
    return [
        (name, dimension, normalisation)
        for name in registry.names("solver")
        for dimension, normalisation in registry.get("solver", name).normalisations.items()
    ]


@pytest.mark.parametrize("solver, dimension, normalisation", built_in_normalisations())
def test_each_symbol_of_each_built_in_solvers_f_is_explained(solver, dimension, normalisation):
    assert symbols_of(normalisation.formula), normalisation.formula
    assert set(symbols_of(normalisation.formula)) <= set(explained(normalisation.definition)), normalisation.definition


def test_the_contact_modulus_is_said_with_poissons_ratio():
    n = ForceNormalisation(load="force", modulus="E*", extent="length")
    assert "E* = E / (1 - nu^2) the contact modulus" in n.definition.split(", ")


def test_a_modulus_of_a_plugins_own_is_named_or_said_in_its_words():
    plain = ForceNormalisation(load="force", modulus="G", extent="length")
    assert "G the solver's modulus" in plain.definition.split(", ")
    worded = ForceNormalisation(load="force", modulus="G", extent="length", modulus_words="G the shear modulus")
    assert "G the shear modulus" in worded.definition.split(", ")
    assert "solver's modulus" not in worded.definition
