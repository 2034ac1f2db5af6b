"""The coursework: variants of a chapter, a hand-in's check, two runs compared."""
