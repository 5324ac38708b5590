"""Symbolic check of the paper's exact helix equations (needs sympy: pip install sympy).

Rod on the cylinder r = R with azimuth phi(l), w = dphi/dl, tangent
t = R w e_phi + sqrt(1 - R^2 w^2) e_z, torque M = EI t x dt/dl, force
F = F_r e_r + F_phi e_phi + F_z e_z. Prints the difference between the torque
balance dM/dl + t x F = 0 projected on e_r and on t x e_r and the paper's
Eqs. (M-er) and (M-e2), and the azimuthal force that follows from (M-e2) and
(F-ephi). Run: python docs/checks/paper_equations.py
"""
import sympy as sp

l = sp.symbols("l")
R, EI, A = sp.symbols("R EI A", positive=True)
w = sp.Function("w")(l)
phi = sp.Function("phi")(l)
Fr, Fp, Fz = (sp.Function(n)(l) for n in ("F_r", "F_phi", "F_z"))
er = sp.Matrix([sp.cos(phi), sp.sin(phi), 0])
ep = sp.Matrix([-sp.sin(phi), sp.cos(phi), 0])
ez = sp.Matrix([0, 0, 1])
c = sp.sqrt(1 - R**2 * w**2)
on_curve = {sp.Derivative(phi, l): w}

t = R * w * ep + c * ez
M = EI * t.cross(t.diff(l).subs(on_curve))
balance = M.diff(l).subs(on_curve) + t.cross(Fr * er + Fp * ep + Fz * ez)

paper_Mer = (EI * R / (1 - R**2 * w**2) ** sp.Rational(3, 2)
             * (w**3 * (1 - R**2 * w**2) ** 2 - w.diff(l, 2) * (1 - R**2 * w**2) - R**2 * w * w.diff(l) ** 2)
             - Fp * c + Fz * R * w)
paper_Me2 = -sp.Rational(3, 2) * EI * R * (w**2).diff(l) + Fr
print("(M-er)  ours - paper:", sp.simplify((balance.T * er)[0] - paper_Mer))
print("(M-e2)  ours - paper:", sp.simplify((balance.T * t.cross(er))[0] - paper_Me2))

# (M-e2): F_r = (3/2) EI R (w^2)';  (F-ephi): F_phi' = -w F_r  ->  F_phi = A - EI R w^3
Fr_sol = sp.Rational(3, 2) * EI * R * (w**2).diff(l)
print("F_phi' + w F_r with F_phi = A - EI R w^3:", sp.simplify((A - EI * R * w**3).diff(l) + w * Fr_sol))
print("F_phi' + w F_r with F_phi = A - EI w^3 (paper):", sp.simplify((A - EI * w**3).diff(l) + w * Fr_sol))
