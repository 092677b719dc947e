"""The boundary tags every layer reads: a mesh's facet tags mark Gamma_D (clamped), Gamma_N
(traction) and Gamma_C (contact) with these numbers, and the contact roles a part of Gamma_C may
play (a model declares which of them it takes)."""

GAMMA_D, GAMMA_N, GAMMA_C = 1, 2, 3

#: the contact roles a boundary part may play (a model declares which of them it takes)
CONTACT_ROLES = ("bilateral", "tresca", "coulomb", "normal_compliance")
