"""Networks of the agent: the encoders (Sec. 3.2 and the Fig. 6 ablations), the structural
interactive module (Eq. 4-6), the SAC actor and critic and the auxiliary heads."""

from simoun_wrappers._homes import missing_name


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
