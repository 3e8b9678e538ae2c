"""Networks of the agent: the encoders (Sec. 3.2 and the Fig. 6 ablations), the structural
interactive module (Eq. 4-6), the SAC actor and critic and the auxiliary heads."""
