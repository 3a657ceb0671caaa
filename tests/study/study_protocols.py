"""Protocols the study tests run: small enough to run in seconds, with the phases over two sessions."""


def two_session_protocol(name):
    """Pre-test, training and post-test on 十 in session 1, retention in session 2 after 60 s; 20 s trials."""
    return {
        "format": "calligraphy-study-protocol",
        "version": 1,
        "name": name,
        "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
        "phases": [
            {"phase": "pre-test", "condition": "vision", "characters": ["十"]},
            {"phase": "training", "condition": "haptic", "characters": ["十"]},
            {"phase": "post-test", "condition": "vision", "characters": ["十"]},
            {"phase": "retention", "condition": "vision", "characters": ["十"], "session": 2, "delay_s": 60},
        ],
        "trial": {"max_duration_s": 20},
    }
