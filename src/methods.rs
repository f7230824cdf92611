//! The method catalogue. A method is a composition of a shape function, a particle-to-grid
//! transfer and a time integrator; the paper names are presets over those parts.

use std::fmt;

use crate::benchmarks::limits::{check_count, largest, per_axis_total, power};
use crate::benchmarks::scattered::MAX_GAUSS_POINTS;
use crate::benchmarks::{ParamDefault, ParamKind, ParamSpec};
use crate::params::{get_f64, get_str, get_usize, ParamError, Params};
use crate::reconstruct::{
    BodyForceFit, Degree, Kernel, MassMatrix, NodalVelocity, QuadratureRecipe, Recipe, Solver,
    TaylorRecipe, Weight,
};
use crate::shape::{DomainShape, DualIntegrals, LmeParamError, LocalMaxEnt, DEFAULT_TOLERANCE};

/// Basis functions used on the background grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShapeKind {
    /// Piecewise-linear hat (tensor product in 2D), Gong eq 4.8.
    Linear,
    /// The hat averaged over each particle's domain (GIMP, CPDI; Gong ch. 6).
    Domain(DomainShape),
    /// Quadratic B-splines on the open knot vector 0, 0, 0, h, ..., L, L, L (tensor product
    /// in 2D): cells + 2 DOFs per axis (BSMPM; Steffen et al. 2008, Tielen et al. 2017).
    QuadraticBSpline,
    /// The hat's values with the dual-domain gradient, the hat's gradient averaged over the
    /// material under each node's hat (DDMPM; Zhang, Ma & Giguere 2011), the integrals taken
    /// as given.
    DualDomain(DualIntegrals),
    /// Local maximum-entropy functions on the grid nodes (Arroyo & Ortiz 2006; Molinos et al.
    /// sec 5), with the locality gamma and the neighbour cut-off of the run.
    LocalMaxEnt(LmeSettings),
}

/// The parameters of the LME basis: gamma = beta h^2 and the prior weight exp(-beta r^2) below
/// which a node is left out of a point's stencil.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LmeSettings {
    pub gamma: f64,
    pub tolerance: f64,
}

/// How particle data reaches the grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TransferKind {
    /// Mass-weighted nodal averages (Shepard interpolation with w = M_p N_i), Gong sec 4.3.1.
    Shepard,
    /// Least-squares fits evaluated at nodes and quadrature points (IMPM, IMLS-MPM).
    Quadrature(QuadratureRecipe),
    /// Mass and forces lumped as in `Shepard`, the nodal velocity a least-squares fit of the
    /// particle velocities (improved CPDI, Gong sec 6.6).
    FittedVelocity(Recipe),
    /// The sums of `Shepard` solved with the consistent mass matrix of the particle
    /// quadrature, M_ij = sum_p M_p N_ip N_jp, for the velocity (Wobbes et al. eq 8 with the
    /// full matrix), the acceleration and MUSL's remap.
    ConsistentMass,
    /// Taylor least squares per element: stress fitted freely, density and momentum with the
    /// element's mass and momentum prescribed, integrated by Gauss quadrature (Wobbes et al.
    /// sec 3).
    Taylor(TaylorRecipe),
}

/// How the grid equations are advanced in time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Leapfrog with half-step velocities and the particle update of Gong sec 4.4.
    Leapfrog,
    /// Whole-step velocities, particles moved first, velocity gradient from the nodal
    /// velocity rebuilt from the moved particles (Tran eqs 31-40; Sulsky's MUSL).
    Musl,
    /// Whole-step velocities, particles kicked and moved with the updated nodal velocity and
    /// deformed with it (update stress last, no remap): what the CPLS code of Tran et al.
    /// runs for MPM, CPDI and IMLS-MPM.
    Usl,
    /// Sulsky et al. 1994 as Molinos et al. eqs 21-22 write it: whole-step velocities,
    /// v_p += dt sum_i N_ip a_i, x_p += dt sum_i N_ip v_i with the start-of-step nodal
    /// velocity, the stress from the updated nodal velocity v_i + dt a_i.
    Euler,
    /// Eqs 23-24 (Zhang et al. 2016): the particle update of eqs 21-22 written with nodal
    /// momenta, and the stress from the nodal velocity rebuilt from the updated particle
    /// velocities, which stays bounded where a nodal mass vanishes.
    EulerCorrected,
    /// The explicit Newmark predictor-corrector (gamma = 1/2) of Molinos et al. sec 4 as the
    /// authors' code runs it: the predictor mapped from the particles' v_p + dt/2 a_p every
    /// step, the stress from it, the corrector with half the new acceleration
    /// (`integrate::predictor_corrector`).
    PredictorCorrector,
}

impl IntegratorKind {
    /// The names the `integrator` parameter takes, in the order of `ALL`.
    pub const NAMES: &'static [&'static str] = &[
        "leapfrog",
        "musl",
        "usl",
        "euler",
        "euler_corrected",
        "predictor_corrector",
    ];
    const ALL: [IntegratorKind; 6] = [
        IntegratorKind::Leapfrog,
        IntegratorKind::Musl,
        IntegratorKind::Usl,
        IntegratorKind::Euler,
        IntegratorKind::EulerCorrected,
        IntegratorKind::PredictorCorrector,
    ];

    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Leapfrog => Self::NAMES[0],
            IntegratorKind::Musl => Self::NAMES[1],
            IntegratorKind::Usl => Self::NAMES[2],
            IntegratorKind::Euler => Self::NAMES[3],
            IntegratorKind::EulerCorrected => Self::NAMES[4],
            IntegratorKind::PredictorCorrector => Self::NAMES[5],
        }
    }

    fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Whether the particles carry v^{s-1/2} between steps and start with a half kick: the
    /// leapfrog alone.
    pub fn staggers_velocity(self) -> bool {
        self == IntegratorKind::Leapfrog
    }

    /// Whether the strain rate comes from the nodal velocity rebuilt from the moved
    /// particles (MUSL, eqs 23-24) rather than from the grid solve's.
    pub fn remaps_velocity(self) -> bool {
        matches!(self, IntegratorKind::Musl | IntegratorKind::EulerCorrected)
    }
}

/// Which particle velocity a sample records for the whole-step schemes MUSL and USL.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampledVelocity {
    /// The whole-step v_p^{s} = v_p^{s-1} + dt sum_i N_ip a_i^{s-1} the scheme steps (what
    /// the CPLS code of Tran et al. writes).
    Stepped,
    /// That velocity read as the centred-difference half-step velocity v^{s-1/2} (with
    /// v_i^{s} = v_i^{s-1} + dt a_i^{s-1} and x moved with it, MUSL and USL are the leapfrog
    /// started without its half kick; Wallstedt & Guilkey 2008) and synchronised at the sample
    /// as the leapfrog's: v_p + dt/2 sum_i N_ip a_i^s.
    Centred,
}

impl SampledVelocity {
    pub const NAMES: &'static [&'static str] = &["stepped", "centred"];

    fn from_name(name: &str) -> Option<Self> {
        match name {
            "stepped" => Some(SampledVelocity::Stepped),
            "centred" => Some(SampledVelocity::Centred),
            _ => None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Method {
    pub shape: ShapeKind,
    pub transfer: TransferKind,
    pub integrator: IntegratorKind,
    pub sampled_velocity: SampledVelocity,
}

impl Method {
    /// Whether a sample adds dt/2 sum_i N_ip a_i^s to the particle velocity: the leapfrog's
    /// half-step velocity always, MUSL's and USL's when read as centred differences.
    pub fn synchronises_samples(&self) -> bool {
        self.integrator.staggers_velocity() || self.sampled_velocity == SampledVelocity::Centred
    }

    /// Whether the basis takes the particles' domains from the seed lattice's sub-cells.
    pub fn reads_seed_domains(&self) -> bool {
        matches!(self.shape, ShapeKind::Domain(_))
    }
}

pub struct MethodPreset {
    pub name: &'static str,
    pub method: Method,
    pub source: &'static str,
    pub description: &'static str,
}

const fn recipe(weight: Weight, scale: f64, solver: Solver) -> Recipe {
    Recipe {
        kernel: Kernel { weight, scale },
        degree: Degree::LINEAR,
        solver,
    }
}

/// Gong sec 5.3, eq 5.6: the nodal velocity by linear MLS with the cubic spline.
const IMPM_VELOCITY: Recipe = recipe(Weight::CubicSpline, 1.0, Solver::Mls);

/// Gong sec 5.3: velocity by linear MLS with the cubic spline, density, stress and body
/// force by linear MLS with the quadratic spline at the cell centres.
const IMPM: QuadratureRecipe = QuadratureRecipe {
    velocity: NodalVelocity::Fit(IMPM_VELOCITY),
    fields: recipe(Weight::QuadraticSpline, 1.0, Solver::Mls),
    gauss_points: 1,
    body_force: BodyForceFit::Separate,
};

/// IMPM's field fits and cell-centre quadrature (Gong eqs 5.7-5.14) with the original MPM's
/// mass-weighted nodal velocity in place of eq 5.6: the field half of IMPM alone.
const IMPM_FIELDS: QuadratureRecipe = QuadratureRecipe {
    velocity: NodalVelocity::Shepard,
    ..IMPM
};

/// Tran eqs 24-31: velocity by IMLS with the hat weight, density, stress and body force by
/// IMLS with the quadratic spline at 2 Gauss points per cell and axis, which integrate
/// N_i times a linear field exactly. The quadratic spline is scaled with h as Gong does;
/// `imls_eq27` scales it with 2h as Tran's eq 27 prints.
const IMLS: QuadratureRecipe = QuadratureRecipe {
    velocity: NodalVelocity::Fit(recipe(Weight::Hat, 1.0, Solver::Imls)),
    fields: recipe(Weight::QuadraticSpline, 1.0, Solver::Imls),
    gauss_points: 2,
    body_force: BodyForceFit::Separate,
};

/// IMLS-MPM as the CPLS code of Tran et al. runs it (`Compute_Interpolator_IMLS_MPM`,
/// `Interpolate_Particle_To_Grid_MLS`): the fields at the cell centre (one point per cell),
/// the body force as one fit of rho_p b_p.
const IMLS_CPLS: QuadratureRecipe = QuadratureRecipe {
    gauss_points: 1,
    body_force: BodyForceFit::Product,
    ..IMLS
};

const IMLS_EQ27: QuadratureRecipe = QuadratureRecipe {
    fields: recipe(Weight::QuadraticSpline, 2.0, Solver::Imls),
    ..IMLS
};

/// Wobbes et al. sec 5: quadratic TLS (n_b = 3 in 1D), two Gauss points per element and
/// axis, velocity and acceleration solved with the consistent mass matrix (eqs 9-11).
const TLS: TaylorRecipe = TaylorRecipe {
    degree: 2,
    gauss_points: 2,
    mass: MassMatrix::Consistent,
};

/// TLS with the lumped mass matrix, which sec 3 allows without losing conservation.
const TLS_LUMPED: TaylorRecipe = TaylorRecipe {
    mass: MassMatrix::Lumped,
    ..TLS
};

const fn on_domains(
    shape: DomainShape,
    transfer: TransferKind,
    integrator: IntegratorKind,
) -> Method {
    Method {
        shape: ShapeKind::Domain(shape),
        transfer,
        integrator,
        sampled_velocity: SampledVelocity::Stepped,
    }
}

const fn musl_on(shape: ShapeKind, transfer: TransferKind) -> Method {
    Method {
        shape,
        transfer,
        integrator: IntegratorKind::Musl,
        sampled_velocity: SampledVelocity::Stepped,
    }
}

const PRESETS: &[MethodPreset] = &[
    MethodPreset {
        name: "mpm",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Shepard,
            integrator: IntegratorKind::Leapfrog,
            sampled_velocity: SampledVelocity::Stepped,
        },
        source: "Gong 2015, ch. 4",
        description: "original MPM: linear hat basis, lumped mass, leapfrog",
    },
    MethodPreset {
        name: "mpm_musl",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Shepard,
            integrator: IntegratorKind::Musl,
            sampled_velocity: SampledVelocity::Stepped,
        },
        source: "Sulsky et al. 1994; Tran et al. 2019, eqs 31-40 with Shepard mapping",
        description: "original MPM mapping with the modified update-stress-last step",
    },
    MethodPreset {
        name: "impm",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Quadrature(IMPM),
            integrator: IntegratorKind::Leapfrog,
            sampled_velocity: SampledVelocity::Stepped,
        },
        source: "Gong 2015, ch. 5",
        description: "improved MPM: MLS velocity at nodes, MLS density/stress at cell centres",
    },
    MethodPreset {
        name: "impm_velocity_only",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::FittedVelocity(IMPM_VELOCITY),
            integrator: IntegratorKind::Leapfrog,
            sampled_velocity: SampledVelocity::Stepped,
        },
        source: "Gong 2015, sec 5.3 (eq 5.6 alone), to isolate IMPM's parts",
        description: "IMPM's MLS nodal velocity alone: mass and forces lumped at the particles as \
                      in mpm, leapfrog",
    },
    MethodPreset {
        name: "impm_fields_only",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Quadrature(IMPM_FIELDS),
            integrator: IntegratorKind::Leapfrog,
            sampled_velocity: SampledVelocity::Stepped,
        },
        source: "Gong 2015, sec 5.3 (eqs 5.7-5.14 alone), to isolate IMPM's parts",
        description: "IMPM's MLS density/stress at cell centres alone: the nodal velocity the \
                      mass-weighted average of mpm, leapfrog",
    },
    MethodPreset {
        name: "imls",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Quadrature(IMLS),
            integrator: IntegratorKind::Musl,
            sampled_velocity: SampledVelocity::Stepped,
        },
        source: "Tran, Berzins, Solowski 2019",
        description: "IMLS-MPM: IMLS velocity at nodes, IMLS fields at 2 Gauss points, MUSL",
    },
    MethodPreset {
        name: "imls_cpls",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Quadrature(IMLS_CPLS),
            integrator: IntegratorKind::Usl,
            sampled_velocity: SampledVelocity::Stepped,
        },
        source: "Tran, Berzins, Solowski 2019, as their CPLS code runs it (IMLS_MPM_solver.m)",
        description:
            "IMLS-MPM: IMLS velocity at nodes, IMLS fields and rho b at the cell centre, USL",
    },
    MethodPreset {
        name: "imls_eq27",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Quadrature(IMLS_EQ27),
            integrator: IntegratorKind::Musl,
            sampled_velocity: SampledVelocity::Stepped,
        },
        source: "Tran, Berzins, Solowski 2019, eq 27 as printed",
        description: "IMLS-MPM with the field weight scaled by 2h (support 3h)",
    },
    MethodPreset {
        name: "mpm_tls",
        method: musl_on(ShapeKind::Linear, TransferKind::Taylor(TLS)),
        source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3",
        description: "MPM with the conservative TLS mapping and the consistent mass matrix, MUSL",
    },
    MethodPreset {
        name: "mpm_tls_lumped",
        method: musl_on(ShapeKind::Linear, TransferKind::Taylor(TLS_LUMPED)),
        source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3 (lumped option)",
        description: "MPM with the conservative TLS mapping and the lumped mass matrix, MUSL",
    },
    MethodPreset {
        name: "ugimp",
        method: on_domains(
            DomainShape::FixedBox,
            TransferKind::Shepard,
            IntegratorKind::Leapfrog,
        ),
        source: "Bardenhagen & Kober 2004; Gong 2015, sec 6.3",
        description: "uGIMP: the hat averaged over the initial particle box, leapfrog",
    },
    MethodPreset {
        name: "cpgimp",
        method: on_domains(
            DomainShape::StretchedBox,
            TransferKind::Shepard,
            IntegratorKind::Leapfrog,
        ),
        source: "Bardenhagen & Kober 2004; Gong 2015, sec 6.3",
        description: "cpGIMP: the particle box stretched by the diagonal of F, leapfrog",
    },
    MethodPreset {
        name: "cpdi1",
        method: on_domains(
            DomainShape::Parallelogram,
            TransferKind::Shepard,
            IntegratorKind::Leapfrog,
        ),
        source: "Sadeghirad et al. 2011; Gong 2015, sec 6.4",
        description: "CPDI1: parallelogram domains r_k = F r_k^0, leapfrog",
    },
    MethodPreset {
        name: "cpdi1_musl",
        method: on_domains(
            DomainShape::Parallelogram,
            TransferKind::Shepard,
            IntegratorKind::Musl,
        ),
        source: "Sadeghirad et al. 2011 in the scheme of Tran et al. 2019, eqs 31-40",
        description: "CPDI1 with the modified update-stress-last step",
    },
    MethodPreset {
        name: "cpdi2",
        method: on_domains(
            DomainShape::Quadrilateral,
            TransferKind::Shepard,
            IntegratorKind::Leapfrog,
        ),
        source: "Sadeghirad et al. 2013; Gong 2015, secs 6.5-6.6",
        description: "CPDI2: domain corners moved with the grid velocity, leapfrog",
    },
    MethodPreset {
        name: "cpdi_mls",
        method: on_domains(
            DomainShape::Quadrilateral,
            TransferKind::FittedVelocity(IMPM_VELOCITY),
            IntegratorKind::Leapfrog,
        ),
        source: "Gong 2015, sec 6.6 (improved CPDI)",
        description: "CPDI2 with IMPM's MLS velocity at the nodes (cubic spline), leapfrog",
    },
    MethodPreset {
        name: "lme",
        method: Method {
            shape: ShapeKind::LocalMaxEnt(LmeSettings {
                gamma: f64::NAN,
                tolerance: DEFAULT_TOLERANCE,
            }),
            transfer: TransferKind::Shepard,
            integrator: IntegratorKind::PredictorCorrector,
            sampled_velocity: SampledVelocity::Stepped,
        },
        source: "Molinos, Navas, Pastor, Stickle, secs 4-5",
        description: "local max-ent basis (gamma from the run), lumped mass, predictor-corrector",
    },
    MethodPreset {
        name: "bsmpm",
        method: musl_on(ShapeKind::QuadraticBSpline, TransferKind::Shepard),
        source: "Steffen et al. 2008; Tielen et al. 2017; Wobbes et al. 2018",
        description: "B-spline MPM: quadratic B-splines, open knot vector, lumped mass, MUSL",
    },
    MethodPreset {
        name: "bsmpm_consistent",
        method: musl_on(ShapeKind::QuadraticBSpline, TransferKind::ConsistentMass),
        source: "Wobbes et al. 2018, eq 8 with the consistent mass matrix",
        description: "B-spline MPM with the consistent mass matrix of the particle quadrature, \
                      MUSL",
    },
    MethodPreset {
        name: "ddmpm",
        method: musl_on(
            ShapeKind::DualDomain(DualIntegrals::Particles),
            TransferKind::Shepard,
        ),
        source: "Zhang, Ma & Giguere 2011; Wobbes et al. 2018",
        description: "dual-domain MPM: hat values, gradient averaged by particle sums over each \
                      node's dual domain, lumped mass, MUSL",
    },
    MethodPreset {
        name: "ddmpm_cells",
        method: musl_on(
            ShapeKind::DualDomain(DualIntegrals::ActiveCells),
            TransferKind::Shepard,
        ),
        source: "Zhang, Ma & Giguere 2011, with exact integrals over the cells holding particles",
        description: "dual-domain MPM with the averages integrated exactly over the active cells, \
                      lumped mass, MUSL",
    },
    MethodPreset {
        name: "bsmpm_tls",
        method: musl_on(ShapeKind::QuadraticBSpline, TransferKind::Taylor(TLS)),
        source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3",
        description: "B-spline MPM with the conservative TLS mapping on each knot span, MUSL",
    },
    MethodPreset {
        name: "bsmpm_tls_lumped",
        method: musl_on(
            ShapeKind::QuadraticBSpline,
            TransferKind::Taylor(TLS_LUMPED),
        ),
        source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3 (lumped option)",
        description: "B-spline MPM with the conservative TLS mapping and the lumped mass matrix, \
                      MUSL",
    },
    MethodPreset {
        name: "ddmpm_tls",
        method: musl_on(
            ShapeKind::DualDomain(DualIntegrals::Particles),
            TransferKind::Taylor(TLS),
        ),
        source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3",
        description: "dual-domain MPM with the conservative TLS mapping, MUSL",
    },
    MethodPreset {
        name: "ddmpm_tls_lumped",
        method: musl_on(
            ShapeKind::DualDomain(DualIntegrals::Particles),
            TransferKind::Taylor(TLS_LUMPED),
        ),
        source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3 (lumped option)",
        description:
            "dual-domain MPM with the conservative TLS mapping and the lumped mass matrix, MUSL",
    },
];

pub fn presets() -> &'static [MethodPreset] {
    PRESETS
}

pub fn preset(name: &str) -> Option<&'static MethodPreset> {
    PRESETS.iter().find(|p| p.name == name)
}

pub fn preset_names() -> Vec<&'static str> {
    PRESETS.iter().map(|p| p.name).collect()
}

pub const GAMMA_KEY: &str = "gamma";
pub const LME_TOLERANCE_KEY: &str = "lme_tolerance";
pub const INTEGRATOR_KEY: &str = "integrator";
pub const GAUSS_POINTS_KEY: &str = "gauss_points";
pub const BODY_FORCE_FIT_KEY: &str = "body_force_fit";
pub const SAMPLED_VELOCITY_KEY: &str = "sampled_velocity";

/// Parameters of the method rather than the benchmark, settable in `params` or as matrix axes
/// of any simulation. They have no defaults that enter a run: a run that does not set them has
/// none in its configuration, so run ids of methods that do not use them do not change.
pub const METHOD_PARAMS: &[ParamSpec] = &[
    ParamSpec {
        key: GAMMA_KEY,
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Required,
        unit: "1",
        doc: "LME locality gamma = beta h^2 (LME methods only, which need it)",
    },
    ParamSpec {
        key: LME_TOLERANCE_KEY,
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(DEFAULT_TOLERANCE),
        unit: "1",
        doc: "LME neighbour cut-off: nodes with exp(-beta r^2) below it are left out (LME only)",
    },
    ParamSpec {
        key: INTEGRATOR_KEY,
        kind: ParamKind::Choice(IntegratorKind::NAMES),
        default: ParamDefault::Text("the preset's"),
        unit: "",
        doc: "time integrator in place of the preset's (not for the TLS transfers, which solve \
              their own grid; predictor_corrector with the Shepard transfer only)",
    },
    ParamSpec {
        key: GAUSS_POINTS_KEY,
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Text("the preset's"),
        unit: "1",
        doc: "Gauss points per cell and axis of the field fits (quadrature transfers: impm, imls)",
    },
    ParamSpec {
        key: BODY_FORCE_FIT_KEY,
        kind: ParamKind::Choice(BodyForceFit::NAMES),
        default: ParamDefault::Text("the preset's"),
        unit: "",
        doc: "separate: rho and b fitted apart; product: one fit of rho_p b_p (quadrature \
              transfers only)",
    },
    ParamSpec {
        key: SAMPLED_VELOCITY_KEY,
        kind: ParamKind::Choice(SampledVelocity::NAMES),
        default: ParamDefault::Text("stepped"),
        unit: "",
        doc: "the particle velocity MUSL and USL record: stepped, the whole-step velocity they \
              step; centred, that velocity read as the centred difference's v^{s-1/2} and \
              synchronised by dt/2 sum_i N_ip a_i^s as the leapfrog's (musl and usl only)",
    },
];

/// The method a run uses: the preset, its integrator replaced by the run's `integrator`, its
/// LME basis given the run's gamma and cut-off, its quadrature transfer given the run's Gauss
/// points and body-force fit. Checks that the run's method parameters apply to the preset and
/// are valid in `dim` dimensions.
pub fn resolve(preset: &MethodPreset, params: &Params, dim: usize) -> Result<Method, ParamError> {
    let mut method = preset.method;
    if let ShapeKind::LocalMaxEnt(lme) = &mut method.shape {
        if !params.contains_key(GAMMA_KEY) {
            // Placed at the method, which is what was written.
            return Err(ParamError::new(
                "method",
                format!(
                    "method {} needs {GAMMA_KEY} (the LME locality beta h^2), e.g. \
                     {GAMMA_KEY}: [0.8, 3.0]",
                    preset.name
                ),
            ));
        }
        lme.gamma = get_f64(params, GAMMA_KEY)?;
        if params.contains_key(LME_TOLERANCE_KEY) {
            lme.tolerance = get_f64(params, LME_TOLERANCE_KEY)?;
        }
        check_lme(lme, dim)?;
    } else {
        refuse(
            params,
            &[GAMMA_KEY, LME_TOLERANCE_KEY],
            preset,
            "LME methods",
            |m| matches!(m.shape, ShapeKind::LocalMaxEnt(_)),
        )?;
    }
    if params.contains_key(INTEGRATOR_KEY) {
        let name = get_str(params, INTEGRATOR_KEY)?;
        let integrator = IntegratorKind::from_name(name).ok_or_else(|| {
            ParamError::new(
                INTEGRATOR_KEY,
                format!(
                    "unknown integrator '{name}'; valid: {}",
                    IntegratorKind::NAMES.join(", ")
                ),
            )
        })?;
        if integrator != preset.method.integrator {
            check_integrator(preset, integrator)?;
        }
        method.integrator = integrator;
    }
    if params.contains_key(SAMPLED_VELOCITY_KEY) {
        method.sampled_velocity = sampled_velocity(preset, params, method.integrator)?;
    }
    if let TransferKind::Quadrature(recipe) = &mut method.transfer {
        if params.contains_key(GAUSS_POINTS_KEY) {
            recipe.gauss_points = get_usize(params, GAUSS_POINTS_KEY)?;
        }
        check_gauss_points(recipe.gauss_points, params, dim)?;
        if params.contains_key(BODY_FORCE_FIT_KEY) {
            let name = get_str(params, BODY_FORCE_FIT_KEY)?;
            recipe.body_force = BodyForceFit::from_name(name).ok_or_else(|| {
                ParamError::new(
                    BODY_FORCE_FIT_KEY,
                    format!(
                        "unknown body_force_fit '{name}'; valid: {}",
                        BodyForceFit::NAMES.join(", ")
                    ),
                )
            })?;
        }
    } else {
        refuse(
            params,
            &[GAUSS_POINTS_KEY, BODY_FORCE_FIT_KEY],
            preset,
            "the quadrature transfers",
            |m| matches!(m.transfer, TransferKind::Quadrature(_)),
        )?;
    }
    Ok(method)
}

/// The run's `sampled_velocity`, which only the whole-step schemes MUSL and USL have a choice of.
fn sampled_velocity(
    preset: &MethodPreset,
    params: &Params,
    integrator: IntegratorKind,
) -> Result<SampledVelocity, ParamError> {
    let name = get_str(params, SAMPLED_VELOCITY_KEY)?;
    let sampled = SampledVelocity::from_name(name).ok_or_else(|| {
        ParamError::new(
            SAMPLED_VELOCITY_KEY,
            format!(
                "unknown sampled_velocity '{name}'; valid: {}",
                SampledVelocity::NAMES.join(", ")
            ),
        )
    })?;
    if matches!(integrator, IntegratorKind::Musl | IntegratorKind::Usl) {
        return Ok(sampled);
    }
    Err(ParamError::new(
        SAMPLED_VELOCITY_KEY,
        format!(
            "{SAMPLED_VELOCITY_KEY} applies to the musl and usl integrators only, not to {} with \
             {integrator}; put those runs in a matrix block of their own",
            preset.name
        ),
    ))
}

/// Refuses the first of `keys` the run sets: they apply to `which` only (the presets that
/// satisfy `applies`), not to `preset`; put such runs in a matrix block of their own.
fn refuse(
    params: &Params,
    keys: &[&str],
    preset: &MethodPreset,
    which: &str,
    applies: impl Fn(&Method) -> bool,
) -> Result<(), ParamError> {
    match keys.iter().find(|key| params.contains_key(**key)) {
        None => Ok(()),
        Some(key) => Err(ParamError::new(
            key,
            format!(
                "{key} applies to {which} only ({}), not to {}; put those runs in a matrix block \
                 of their own",
                preset_names_where(applies).join(", "),
                preset.name
            ),
        )),
    }
}

/// Refuses an `integrator` the preset's transfer cannot run, naming the presets that can.
fn check_integrator(preset: &MethodPreset, integrator: IntegratorKind) -> Result<(), ParamError> {
    if runs_with(&preset.method, integrator) {
        return Ok(());
    }
    Err(ParamError::new(
        INTEGRATOR_KEY,
        format!(
            "{} maps with {}, which cannot run {integrator}; {integrator} runs with the methods \
             {}",
            preset.name,
            preset.method.transfer,
            preset_names_where(|m| runs_with(m, integrator)).join(", ")
        ),
    ))
}

/// Whether `method`'s transfer can run `integrator`: the TLS and consistent-mass transfers
/// solve the grid with their own mass matrix, so they keep their integrator; the predictor-corrector maps its
/// predictor with the Shepard transfer.
fn runs_with(method: &Method, integrator: IntegratorKind) -> bool {
    match method.transfer {
        TransferKind::Taylor(_) | TransferKind::ConsistentMass => integrator == method.integrator,
        TransferKind::Shepard => true,
        TransferKind::Quadrature(_) | TransferKind::FittedVelocity(_) => {
            integrator != IntegratorKind::PredictorCorrector
        }
    }
}

/// The quadrature transfers fit the fields at `gauss_points` per cell and axis of the grid:
/// at most `MAX_GAUSS_POINTS`, and at most `MAX_POINTS` in all.
fn check_gauss_points(gauss_points: usize, params: &Params, dim: usize) -> Result<(), ParamError> {
    if gauss_points > MAX_GAUSS_POINTS {
        return Err(ParamError::new(
            GAUSS_POINTS_KEY,
            format!(
                "{GAUSS_POINTS_KEY} = {gauss_points}: at most {MAX_GAUSS_POINTS} Gauss points per \
                 cell and axis"
            ),
        ));
    }
    let cells = get_usize(params, "cells")?;
    let extra = match params.get("extra_cells") {
        Some(_) => get_usize(params, "extra_cells")?,
        None => 0,
    };
    let per_axis = cells
        .checked_add(extra)
        .and_then(|n| n.checked_mul(gauss_points));
    check_count(
        per_axis.and_then(|n| per_axis_total(n, dim)),
        "Gauss points",
        &format!(
            "((cells + extra_cells) {GAUSS_POINTS_KEY}){} with cells = {cells}, extra_cells = \
             {extra} and {GAUSS_POINTS_KEY} = {gauss_points}",
            power(dim)
        ),
        largest(&[("cells", cells), (GAUSS_POINTS_KEY, gauss_points)]),
    )
}

fn check_lme(lme: &LmeSettings, dim: usize) -> Result<(), ParamError> {
    let valid: Result<(), LmeParamError> = match dim {
        1 => LocalMaxEnt::<1>::with_tolerance(lme.gamma, lme.tolerance).map(drop),
        _ => LocalMaxEnt::<2>::with_tolerance(lme.gamma, lme.tolerance).map(drop),
    };
    valid.map_err(|e| ParamError::new(GAMMA_KEY, e.to_string()))
}

/// The presets whose composition satisfies `keep`.
fn preset_names_where(keep: impl Fn(&Method) -> bool) -> Vec<&'static str> {
    PRESETS
        .iter()
        .filter(|p| keep(&p.method))
        .map(|p| p.name)
        .collect()
}

impl fmt::Display for ShapeKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ShapeKind::Linear => f.write_str("linear"),
            ShapeKind::Domain(shape) => write!(f, "domain({shape})"),
            ShapeKind::QuadraticBSpline => f.write_str("quadratic-bspline"),
            ShapeKind::DualDomain(DualIntegrals::Particles) => {
                f.write_str("dual-domain(particles)")
            }
            ShapeKind::DualDomain(DualIntegrals::ActiveCells) => f.write_str("dual-domain(cells)"),
            ShapeKind::LocalMaxEnt(lme) => {
                write!(f, "lme(gamma={}, tolerance={})", lme.gamma, lme.tolerance)
            }
        }
    }
}

impl fmt::Display for TransferKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TransferKind::Shepard => f.write_str("shepard"),
            TransferKind::ConsistentMass => f.write_str("consistent-mass"),
            TransferKind::Quadrature(recipe) => write!(f, "quadrature({recipe})"),
            TransferKind::FittedVelocity(recipe) => write!(f, "fitted-velocity({recipe})"),
            TransferKind::Taylor(recipe) => write!(f, "taylor({recipe})"),
        }
    }
}

impl fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "shape={} transfer={} integrate={}",
            self.shape, self.transfer, self.integrator
        )?;
        if self.sampled_velocity == SampledVelocity::Centred {
            f.write_str(" sampled=centred")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_integrator_is_found_by_its_name() {
        for kind in IntegratorKind::ALL {
            assert_eq!(IntegratorKind::from_name(kind.name()), Some(kind));
        }
        let names: Vec<&str> = IntegratorKind::ALL.iter().map(|k| k.name()).collect();
        assert_eq!(names, IntegratorKind::NAMES);
        assert_eq!(IntegratorKind::from_name("rk4"), None);
    }
}
