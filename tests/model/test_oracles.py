"""The oracles' one table (model/oracles.py): the solver's names, from the
build's solver_defaults.json, each with the add-on's words."""

import unittest

from model import oracles, quality_meaning
from model.solver_defaults import SOLVER_DEFAULTS


class OraclesTest(unittest.TestCase):
    def test_the_names_are_the_solvers(self):
        self.assertEqual(list(oracles.NAMES), SOLVER_DEFAULTS["oracles"])
        self.assertIn(SOLVER_DEFAULTS["oracle"], oracles.NAMES)
        self.assertEqual(set(oracles.WORDING), set(oracles.NAMES))

    def test_the_settings_items_follow_the_solvers_order(self):
        self.assertEqual([item[0] for item in oracles.ENUM_ITEMS], list(oracles.IDENTIFIERS))
        for name, (identifier, label, description) in zip(oracles.NAMES, oracles.ENUM_ITEMS):
            self.assertEqual(oracles.name_of(identifier), name)
            self.assertEqual(oracles.identifier(name), identifier)
            self.assertTrue(label and description)
            self.assertIn("(%s)" % label, oracles.SETTING_DESCRIPTION)

    def test_every_oracle_says_what_quality_means(self):
        for identifier in oracles.IDENTIFIERS:
            headline, detail = quality_meaning.quality_meaning(identifier, 0.01)
            self.assertTrue(headline and detail, identifier)


if __name__ == "__main__":
    unittest.main()
