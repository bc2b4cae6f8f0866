"""The field simulator: pymunk physics, referee basics, overhead camera rendering, scripted play.

The simulator must not know how the team sees or thinks: it imports only the project's floor
(``cmdragons.config``, ``cmdragons.geometry``, ``cmdragons.camera``, ``cmdragons.messages``).
"""
