"""Mitsuba 3 BSDF plugin for specula's `pow` lobe (hand-written template).

specula's generator will emit one file like this per lobe, so everything here is written
with Dr.Jit operations only (`dr.*`, `mi.*`): the same code runs in `scalar_rgb` (one
direction per call) and in the JIT variants such as `llvm_ad_rgb` (arrays of directions).
No Python `if` ever looks at a Dr.Jit value; masks go through `dr.select`.

Conventions (specula's, in the local frame where z is the normal):
- specula's `wo` (towards the viewer) is Mitsuba's `si.wi`;
- specula's `wi` (towards the light) is the `wo` Mitsuba passes to `eval`/`pdf`;
- BRDF  f = kd / pi + ks N(n) lobe(t),  lobe(t) = t^n on (0, 1], 0 for t <= 0, 1 past 1;
- Mitsuba's `eval` returns f cos(theta_i) (its convention), 0 below either horizon.

Importing this file registers the plugin as `specula_pow`.
"""

import drjit as dr
import mitsuba as mi

# Rec. 709 luminance, as specula weighs the two terms when it splits BRDF draws (not
# `mi.luminance`, whose weights differ in the fourth digit).
LUMINANCE = (0.2126, 0.7152, 0.0722)

GEOMETRIES = ("phong", "blinn")
NORMALISATIONS = ("none", "lobe", "phong", "blinn")

# specula's exponents are bounded; outside this range the generated code is not tested.
N_RANGE = (1.0, 1000.0)


def _rgb(props, name, default):
    """A float or rgb property as three Python floats (XML <rgb>, a dict list or a float)."""
    value = props.get(name, default)
    if isinstance(value, (int, float)):
        return [float(value)] * 3
    return [float(value[0]), float(value[1]), float(value[2])]


def _choice(props, name, default, allowed):
    value = str(props.get(name, default))
    if value not in allowed:
        raise ValueError("specula_pow: %s must be one of %s, not %r" % (name, allowed, value))
    return value


def lobe_integral(n):
    """L = int_0^1 t^n dt: the lobe's mass, which normalises its sampling density."""
    return 1.0 / (n + 1.0)


def normalisation_constant(normalisation, n):
    """N(n). specula's generator computes this in Rust and bakes the number in."""
    if normalisation == "none":
        return 1.0
    if normalisation == "lobe":
        return 1.0 / (2.0 * dr.pi * lobe_integral(n))
    if normalisation == "phong":
        return (n + 2.0) / (2.0 * dr.pi)
    return (n + 8.0) / (8.0 * dr.pi)  # "blinn"


def specular_share(kd, ks):
    """Probability that a draw goes to the lobe: lum(ks) / (lum(ks) + lum(kd)), 1 if both 0."""
    lum = lambda c: sum(w * x for w, x in zip(LUMINANCE, c))
    total = lum(kd) + lum(ks)
    return lum(ks) / total if total > 0.0 else 1.0


class SpeculaPow(mi.BSDF):
    def __init__(self, props):
        mi.BSDF.__init__(self, props)
        self.n = float(props.get("n", 64.0))
        if not N_RANGE[0] <= self.n <= N_RANGE[1]:
            raise ValueError("specula_pow: n must lie in [1, 1000], not %g" % self.n)
        self.kd_rgb = _rgb(props, "kd", 0.0)
        self.ks_rgb = _rgb(props, "ks", 1.0)
        self.geometry = _choice(props, "geometry", "phong", GEOMETRIES)
        self.normalisation = _choice(props, "normalisation", "lobe", NORMALISATIONS)
        self.kd = mi.Color3f(*self.kd_rgb)
        self.ks = mi.Color3f(*self.ks_rgb)
        self.norm = normalisation_constant(self.normalisation, self.n)
        # Solid-angle density of the lobe about its axis is lobe(t) / (2 pi L).
        self.density_scale = 1.0 / (2.0 * dr.pi * lobe_integral(self.n))
        self.p_spec = specular_share(self.kd_rgb, self.ks_rgb)
        self._set_flags()

    def _set_flags(self):
        # Component 0 is the lobe, component 1 (only with kd > 0) the diffuse term.
        glossy = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
        components = [glossy]
        if max(self.kd_rgb) > 0.0:
            components.append(mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide)
        self.m_components = components
        flags = components[0]
        for c in components[1:]:
            flags = flags | c
        self.m_flags = flags

    # ----------------------------------------------------------------- the model

    def _lobe(self, t):
        """t^n on (0, 1], 1 above 1 (rounding past the peak), 0 for t <= 0 and NaN."""
        clamped = dr.minimum(t, 1.0)
        return dr.select(t > 0.0, dr.exp(self.n * dr.log(clamped)), 0.0)

    def _half(self, wo, wi):
        return dr.normalize(wo + wi)

    def _cosine(self, wo, wi):
        """The lobe's argument t: r.wi about the mirror (Phong) or h.z (Blinn)."""
        if self.geometry == "phong":  # a Python string: fixed per material, not traced
            return dr.dot(mi.reflect(wo), wi)
        return self._half(wo, wi).z

    def _spec_pdf(self, wo, wi):
        """Solid-angle density of a lobe draw at wi (before the horizon test)."""
        if self.geometry == "phong":
            return self._lobe(dr.dot(mi.reflect(wo), wi)) * self.density_scale
        h = self._half(wo, wi)
        cos_oh = dr.dot(wo, h)
        around = self._lobe(h.z) * self.density_scale
        return dr.select(cos_oh > 0.0, around / (4.0 * cos_oh), 0.0)

    def _mixture_pdf(self, wo, wi, valid):
        p = self.p_spec * self._spec_pdf(wo, wi) + (1.0 - self.p_spec) * (
            mi.warp.square_to_cosine_hemisphere_pdf(wi))
        return dr.select(valid, p, 0.0)

    def _brdf_cos(self, wo, wi, valid):
        """f(wo, wi) cos(theta_i), the quantity Mitsuba's eval returns."""
        f = self.kd * dr.inv_pi + self.ks * (self.norm * self._lobe(self._cosine(wo, wi)))
        return dr.select(valid, f * mi.Frame3f.cos_theta(wi), mi.Color3f(0.0))

    def _valid(self, wo, wi, active):
        return active & (mi.Frame3f.cos_theta(wo) > 0.0) & (mi.Frame3f.cos_theta(wi) > 0.0)

    # ----------------------------------------------------------------- sampling

    def _sample_lobe(self, wo, u):
        """A lobe draw (wi, ok): t = (1 - u)^(1/(n+1)) inverts the tail integral of
        lobe(t) / L, and phi = 2 pi u2.

        Dr.Jit 1.5 has no log1p, so (1 - u)^(1/(n+1)) is exp(log(1 - u) / (n + 1)); the
        rounding of 1 - u near u = 0 moves t by less than float32's resolution at 1.
        """
        t = dr.exp(dr.log(1.0 - u.x) / (self.n + 1.0))
        sin_t = dr.safe_sqrt(dr.fma(-t, t, 1.0))
        s, c = dr.sincos(dr.two_pi * u.y)
        around = mi.Vector3f(sin_t * c, sin_t * s, t)
        if self.geometry == "phong":  # about the mirror direction r
            return mi.Frame3f(mi.reflect(wo)).to_world(around), True
        # Blinn: `around` is the half vector h about the normal; wi is wo mirrored about h,
        # and a draw with wo.h <= 0 is refused (it would mirror wo through the surface).
        cos_oh = dr.dot(wo, around)
        return 2.0 * cos_oh * around - wo, cos_oh > 0.0

    def sample(self, ctx, si, sample1, sample2, active=True):
        # sample1 picks the term and sample2 draws within it, as specula's renderer does
        # with u[0] and u[1..3] (and as Mitsuba's roughplastic does): nothing to rescale.
        wo = si.wi
        pick_spec = sample1 < self.p_spec
        lobe_wi, lobe_ok = self._sample_lobe(wo, sample2)
        wi = dr.select(pick_spec, lobe_wi, mi.warp.square_to_cosine_hemisphere(sample2))
        wi = dr.normalize(wi)
        # dr.select, not `~pick_spec | lobe_ok`: in scalar_rgb these are Python bools, where
        # `~True` is the integer -2.
        valid = self._valid(wo, wi, active) & dr.select(pick_spec, lobe_ok, True)
        pdf = self._mixture_pdf(wo, wi, valid)
        valid &= pdf > 0.0

        bs = mi.BSDFSample3f()
        bs.wo = wi
        bs.pdf = dr.select(valid, pdf, 0.0)
        bs.eta = 1.0
        bs.sampled_component = dr.select(pick_spec, mi.UInt32(0), mi.UInt32(1))
        bs.sampled_type = dr.select(pick_spec, mi.UInt32(+mi.BSDFFlags.GlossyReflection),
                                    mi.UInt32(+mi.BSDFFlags.DiffuseReflection))
        # f cos / pdf, with the mixture pdf (both terms could have drawn wi).
        value = self._brdf_cos(wo, wi, valid)
        weight = dr.select(valid, value / dr.select(valid, pdf, 1.0), mi.Color3f(0.0))
        return bs, weight

    # ----------------------------------------------------------------- evaluation
    # Mitsuba's `wo` here is specula's wi (the helpers above take specula's (wo, wi)). The
    # context's component/type mask is not consulted: every lobe is always on, which is what
    # the `direct` and `path` integrators ask for.

    def eval(self, ctx, si, wo, active=True):
        return self._brdf_cos(si.wi, wo, self._valid(si.wi, wo, active))

    def pdf(self, ctx, si, wo, active=True):
        return self._mixture_pdf(si.wi, wo, self._valid(si.wi, wo, active))

    def eval_pdf(self, ctx, si, wo, active=True):
        valid = self._valid(si.wi, wo, active)
        return self._brdf_cos(si.wi, wo, valid), self._mixture_pdf(si.wi, wo, valid)

    # ----------------------------------------------------------------- bookkeeping

    def traverse(self, callback):
        callback.put("kd", self.kd, mi.ParamFlags.Differentiable)
        callback.put("ks", self.ks, mi.ParamFlags.Differentiable)

    def parameters_changed(self, keys=[]):
        # The lobe/diffuse split follows the colours; it is kept a Python float (read back
        # once per update) so the sampling code is the same in every variant.
        self.kd_rgb = [float(dr.slice(self.kd[i])) for i in range(3)]
        self.ks_rgb = [float(dr.slice(self.ks[i])) for i in range(3)]
        self.p_spec = specular_share(self.kd_rgb, self.ks_rgb)
        self._set_flags()

    def to_string(self):
        return ("SpeculaPow[n=%g, geometry=%s, normalisation=%s, kd=%s, ks=%s, N=%g, "
                "p_spec=%g]" % (self.n, self.geometry, self.normalisation, self.kd_rgb,
                                self.ks_rgb, self.norm, self.p_spec))


mi.register_bsdf("specula_pow", lambda props: SpeculaPow(props))
