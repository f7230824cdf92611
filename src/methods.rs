//! The method catalogue. A method is a composition of a shape function, a particle-to-grid
//! transfer and a time integrator; the paper names are presets over those parts.

use std::fmt;

use crate::benchmarks::limits::{check_count, largest, per_axis_total, power};
use crate::benchmarks::scattered::MAX_GAUSS_POINTS;
use crate::benchmarks::{ParamDefault, ParamKind, ParamSpec};
use crate::catalog::{names_of, Catalog, Entry, Named, Parts};
use crate::grid::Dofs;
use crate::integrate::{IntegratorKind, INTEGRATORS, INTEGRATOR_NAMES};
use crate::params::{get_f64, get_str, get_usize, ParamError, Params};
use crate::reconstruct::{
    TransferKind, BODY_FORCE_FITS, BODY_FORCE_FIT_NAMES, IMLS, IMLS_CPLS, IMLS_EQ27, IMPM,
    IMPM_FIELDS, IMPM_VELOCITY, TLS, TLS_LUMPED, TRANSFERS, TRANSFER_NAMES,
};
use crate::shape::{
    DomainShape, DualIntegrals, LmeParamError, LmeSettings, LocalMaxEnt, ShapeKind, SplineDegree,
    DEFAULT_TOLERANCE, LME_UNSET, SHAPES, SHAPE_NAMES,
};

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

const SAMPLED_VELOCITY_ENTRIES: &[Entry<SampledVelocity>] = &[
    Entry {
        name: "stepped",
        value: SampledVelocity::Stepped,
        description: "the whole-step velocity the scheme steps",
    },
    Entry {
        name: "centred",
        value: SampledVelocity::Centred,
        description: "that velocity read as v^{s-1/2} and synchronised as the leapfrog's",
    },
];

pub const SAMPLED_VELOCITIES: Parts<SampledVelocity> = Catalog {
    kind: "sampled_velocity",
    entries: SAMPLED_VELOCITY_ENTRIES,
};

const SAMPLED_VELOCITY_NAMES: [&str; SAMPLED_VELOCITY_ENTRIES.len()] =
    names_of(SAMPLED_VELOCITY_ENTRIES);

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
        self.shape.reads_seed_domains()
    }
}

pub struct MethodPreset {
    pub name: &'static str,
    pub method: Method,
    pub source: &'static str,
    pub description: &'static str,
}

impl Named for MethodPreset {
    fn name(&self) -> &'static str {
        self.name
    }
}

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

pub const PRESETS: Catalog<MethodPreset> = Catalog {
    kind: "method",
    entries: &[
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
            description:
                "IMPM's MLS nodal velocity alone: mass and forces lumped at the particles as \
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
            description:
                "MPM with the conservative TLS mapping and the consistent mass matrix, MUSL",
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
                shape: LME_UNSET,
                transfer: TransferKind::Shepard,
                integrator: IntegratorKind::PredictorCorrector,
                sampled_velocity: SampledVelocity::Stepped,
            },
            source: "Molinos, Navas, Pastor, Stickle, secs 4-5",
            description:
                "local max-ent basis (gamma from the run), lumped mass, predictor-corrector",
        },
        MethodPreset {
            name: "bsmpm",
            method: musl_on(
                ShapeKind::BSpline(SplineDegree::Quadratic),
                TransferKind::Shepard,
            ),
            source: "Steffen et al. 2008; Tielen et al. 2017; Wobbes et al. 2018",
            description: "B-spline MPM: quadratic B-splines, open knot vector, lumped mass, MUSL",
        },
        MethodPreset {
            name: "bsmpm_cubic",
            method: musl_on(
                ShapeKind::BSpline(SplineDegree::Cubic),
                TransferKind::Shepard,
            ),
            source: "Steffen et al. 2008, with the cubic B-spline",
            description: "B-spline MPM: cubic B-splines, open knot vector, lumped mass, MUSL",
        },
        MethodPreset {
            name: "bsmpm_consistent",
            method: musl_on(
                ShapeKind::BSpline(SplineDegree::Quadratic),
                TransferKind::ConsistentMass,
            ),
            source: "Wobbes et al. 2018, eq 8 with the consistent mass matrix",
            description:
                "B-spline MPM with the consistent mass matrix of the particle quadrature, \
                      MUSL",
        },
        MethodPreset {
            name: "ddmpm",
            method: musl_on(
                ShapeKind::DualDomain(DualIntegrals::Particles),
                TransferKind::Shepard,
            ),
            source: "Zhang, Ma & Giguere 2011; Wobbes et al. 2018",
            description:
                "dual-domain MPM: hat values, gradient averaged by particle sums over each \
                      node's dual domain, lumped mass, MUSL",
        },
        MethodPreset {
            name: "ddmpm_cells",
            method: musl_on(
                ShapeKind::DualDomain(DualIntegrals::ActiveCells),
                TransferKind::Shepard,
            ),
            source:
                "Zhang, Ma & Giguere 2011, with exact integrals over the cells holding particles",
            description:
                "dual-domain MPM with the averages integrated exactly over the active cells, \
                      lumped mass, MUSL",
        },
        MethodPreset {
            name: "bsmpm_tls",
            method: musl_on(
                ShapeKind::BSpline(SplineDegree::Quadratic),
                TransferKind::Taylor(TLS),
            ),
            source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3",
            description: "B-spline MPM with the conservative TLS mapping on each knot span, MUSL",
        },
        MethodPreset {
            name: "bsmpm_tls_lumped",
            method: musl_on(
                ShapeKind::BSpline(SplineDegree::Quadratic),
                TransferKind::Taylor(TLS_LUMPED),
            ),
            source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3 (lumped option)",
            description:
                "B-spline MPM with the conservative TLS mapping and the lumped mass matrix, \
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
        MethodPreset {
            name: COMPOSED,
            method: Method {
                shape: ShapeKind::Linear,
                transfer: TransferKind::Shepard,
                integrator: IntegratorKind::Leapfrog,
                sampled_velocity: SampledVelocity::Stepped,
            },
            source: "the run's parts",
            description: "the composition of the run's shape, transfer and integrator (all three \
                      required; `mpmlab list-methods` lists each part)",
        },
    ],
};

/// The preset that is no preset: a method composed of the run's `shape`, `transfer` and
/// `integrator` alone.
pub const COMPOSED: &str = "composed";

pub const SHAPE_KEY: &str = "shape";
pub const TRANSFER_KEY: &str = "transfer";
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
        key: SHAPE_KEY,
        kind: ParamKind::Choice(&SHAPE_NAMES),
        default: ParamDefault::Text("the preset's"),
        unit: "",
        doc: "shape function in place of the preset's (`mpmlab list-methods` describes each)",
    },
    ParamSpec {
        key: TRANSFER_KEY,
        kind: ParamKind::Choice(&TRANSFER_NAMES),
        default: ParamDefault::Text("the preset's"),
        unit: "",
        doc: "particle-to-grid transfer in place of the preset's (`mpmlab list-methods` \
              describes each)",
    },
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
        kind: ParamKind::Choice(&INTEGRATOR_NAMES),
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
        kind: ParamKind::Choice(&BODY_FORCE_FIT_NAMES),
        default: ParamDefault::Text("the preset's"),
        unit: "",
        doc: "separate: rho and b fitted apart; product: one fit of rho_p b_p (quadrature \
              transfers only)",
    },
    ParamSpec {
        key: SAMPLED_VELOCITY_KEY,
        kind: ParamKind::Choice(&SAMPLED_VELOCITY_NAMES),
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
    let parts = [SHAPE_KEY, TRANSFER_KEY, INTEGRATOR_KEY];
    if preset.name == COMPOSED {
        if let Some(key) = parts.iter().find(|key| !params.contains_key(**key)) {
            return Err(ParamError::new(
                "method",
                format!(
                    "method {COMPOSED} needs {}: {key} is not set",
                    parts.join(", ")
                ),
            ));
        }
    }
    if let Some(shape) = named_part(params, SHAPE_KEY, &SHAPES)? {
        method.shape = shape;
    }
    if let Some(transfer) = named_part(params, TRANSFER_KEY, &TRANSFERS)? {
        method.transfer = transfer;
    }
    if let Err(reason) = check_parts(&method) {
        let key = parts[..2]
            .iter()
            .find(|key| params.contains_key(**key))
            .unwrap_or(&"method");
        return Err(ParamError::new(key, reason));
    }
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
    if let Some(integrator) = named_part(params, INTEGRATOR_KEY, &INTEGRATORS)? {
        check_integrator(preset, &method, integrator)?;
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
        if let Some(fit) = named_part(params, BODY_FORCE_FIT_KEY, &BODY_FORCE_FITS)? {
            recipe.body_force = fit;
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

/// The part the run names under `key`, looked up in `parts`; `None` where it names none.
fn named_part<T: Copy>(
    params: &Params,
    key: &str,
    parts: &Parts<T>,
) -> Result<Option<T>, ParamError> {
    if !params.contains_key(key) {
        return Ok(None);
    }
    let name = get_str(params, key)?;
    let entry = parts.get(name).map_err(|e| ParamError::new(key, e))?;
    Ok(Some(entry.value))
}

/// The run's `sampled_velocity`, which only the whole-step schemes MUSL and USL have a choice of.
fn sampled_velocity(
    preset: &MethodPreset,
    params: &Params,
    integrator: IntegratorKind,
) -> Result<SampledVelocity, ParamError> {
    let sampled = named_part(params, SAMPLED_VELOCITY_KEY, &SAMPLED_VELOCITIES)?
        .expect("called where the run sets sampled_velocity");
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

/// Refuses an `integrator` the method's transfer cannot run, naming the presets and the
/// transfers that can.
fn check_integrator(
    preset: &MethodPreset,
    method: &Method,
    integrator: IntegratorKind,
) -> Result<(), ParamError> {
    if runs_with(&method.transfer, integrator) {
        return Ok(());
    }
    let transfers: Vec<&str> = TRANSFERS
        .entries
        .iter()
        .filter(|e| runs_with(&e.value, integrator))
        .map(|e| e.name)
        .collect();
    let mapping = match TRANSFERS.name_of(&method.transfer) {
        Some(name) if preset.name == COMPOSED => format!("the {name} transfer"),
        _ => format!("{} maps with {}", preset.name, method.transfer),
    };
    Err(ParamError::new(
        INTEGRATOR_KEY,
        format!(
            "{mapping}, which cannot run {integrator}; {integrator} runs with the methods {} (the \
             transfers {})",
            preset_names_where(|m| runs_with(&m.transfer, integrator)).join(", "),
            transfers.join(", ")
        ),
    ))
}

/// Whether `transfer` can run `integrator`: the TLS and consistent-mass transfers solve the
/// grid with their own mass matrix inside MUSL's steps; the predictor-corrector maps its
/// predictor with the Shepard transfer.
fn runs_with(transfer: &TransferKind, integrator: IntegratorKind) -> bool {
    match transfer {
        TransferKind::Taylor(_) | TransferKind::ConsistentMass => {
            integrator == IntegratorKind::Musl
        }
        TransferKind::Shepard => true,
        TransferKind::Quadrature(_) | TransferKind::FittedVelocity(_) => {
            integrator != IntegratorKind::PredictorCorrector
        }
    }
}

/// Why a shape function and a transfer cannot run together, if they cannot.
pub fn check_parts(method: &Method) -> Result<(), String> {
    let (runs_on, reason): (fn(&ShapeKind) -> bool, &str) = match method.transfer {
        TransferKind::Quadrature(_) => (
            |shape| *shape == ShapeKind::Linear,
            "its fits evaluate the linear hat at their own quadrature points",
        ),
        TransferKind::FittedVelocity(_) => (
            |shape| shape.dofs() == Dofs::Nodes,
            "it fits the velocity at the grid nodes, which must be the basis's DOFs",
        ),
        TransferKind::ConsistentMass | TransferKind::Taylor(_) | TransferKind::Shepard => {
            return Ok(())
        }
    };
    if runs_on(&method.shape) {
        return Ok(());
    }
    let valid: Vec<&str> = SHAPES
        .entries
        .iter()
        .filter(|e| runs_on(&e.value))
        .map(|e| e.name)
        .collect();
    Err(format!(
        "the {} transfer cannot run on the {} shape function ({reason}); it runs on {}",
        TRANSFERS
            .name_of(&method.transfer)
            .unwrap_or("this transfer"),
        method.shape.name(),
        valid.join(", ")
    ))
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
        .entries
        .iter()
        .filter(|p| p.name != COMPOSED && keep(&p.method))
        .map(|p| p.name)
        .collect()
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
    use crate::params::ParamValue;

    fn params(entries: &[(&str, ParamValue)]) -> Params {
        let mut p: Params = [("cells".to_string(), ParamValue::Int(8))].into();
        p.extend(entries.iter().map(|(k, v)| (k.to_string(), v.clone())));
        p
    }

    fn text(s: &str) -> ParamValue {
        ParamValue::Str(s.into())
    }

    /// The parameters that name a preset's parts, and the gamma an LME basis needs.
    fn parts_of(preset: &MethodPreset) -> Params {
        let m = &preset.method;
        let mut p = params(&[
            (SHAPE_KEY, text(m.shape.name())),
            (TRANSFER_KEY, text(TRANSFERS.name_of(&m.transfer).unwrap())),
            (INTEGRATOR_KEY, text(m.integrator.name())),
        ]);
        if m.shape.name() == "lme" {
            p.insert(GAMMA_KEY.into(), ParamValue::Float(3.0));
        }
        p
    }

    #[test]
    fn every_preset_is_the_composition_of_its_named_parts() {
        let composed = PRESETS.find(COMPOSED).unwrap();
        for preset in PRESETS.entries.iter().filter(|p| p.name != COMPOSED) {
            let parts = parts_of(preset);
            let mut own = params(&[]);
            own.extend(
                parts
                    .get(GAMMA_KEY)
                    .map(|g| (GAMMA_KEY.to_string(), g.clone())),
            );
            for dim in [1, 2] {
                assert_eq!(
                    resolve(composed, &parts, dim),
                    resolve(preset, &own, dim),
                    "{}",
                    preset.name
                );
            }
        }
    }

    #[test]
    fn a_part_given_beside_a_preset_replaces_the_presets() {
        let mpm = PRESETS.find("mpm").unwrap();
        let method = resolve(mpm, &params(&[(TRANSFER_KEY, text("mls_velocity"))]), 1).unwrap();
        assert_eq!(method.transfer, TransferKind::FittedVelocity(IMPM_VELOCITY));
        assert_eq!(
            (method.shape, method.integrator),
            (ShapeKind::Linear, mpm.method.integrator)
        );
        let method = resolve(mpm, &params(&[(SHAPE_KEY, text("cpdi2"))]), 2).unwrap();
        assert_eq!(method.shape, ShapeKind::Domain(DomainShape::Quadrilateral));
    }

    #[test]
    fn parts_that_cannot_run_together_are_refused_with_the_reason() {
        let imls = PRESETS.find("imls").unwrap();
        let e = resolve(imls, &params(&[(SHAPE_KEY, text("quadratic_bspline"))]), 1).unwrap_err();
        assert_eq!(e.key, SHAPE_KEY);
        assert!(
            e.message
                .contains("the imls transfer cannot run on the quadratic_bspline shape")
                && e.message.ends_with("it runs on linear"),
            "{}",
            e.message
        );
        let fitted = PRESETS.find("cpdi_mls").unwrap();
        let e = resolve(
            fitted,
            &params(&[(SHAPE_KEY, text("quadratic_bspline"))]),
            1,
        )
        .unwrap_err();
        assert_eq!(
            e.message,
            "the mls_velocity transfer cannot run on the quadratic_bspline shape function (it fits \
             the velocity at the grid nodes, which must be the basis's DOFs); it runs on linear, \
             ugimp, cpgimp, cpdi1, cpdi2, dual_domain, dual_domain_cells, lme"
        );
        let composed = PRESETS.find(COMPOSED).unwrap();
        let tls_leapfrog = params(&[
            (SHAPE_KEY, text("linear")),
            (TRANSFER_KEY, text("tls")),
            (INTEGRATOR_KEY, text("leapfrog")),
        ]);
        let e = resolve(composed, &tls_leapfrog, 1).unwrap_err();
        assert_eq!(e.key, INTEGRATOR_KEY);
        assert!(
            e.message
                .starts_with("the tls transfer, which cannot run leapfrog;"),
            "{}",
            e.message
        );
        let e = resolve(composed, &params(&[(SHAPE_KEY, text("linear"))]), 1).unwrap_err();
        assert_eq!(e.key, "method");
        assert!(e.message.contains("transfer is not set"), "{}", e.message);
        let e = resolve(imls, &params(&[(TRANSFER_KEY, text("flip"))]), 1).unwrap_err();
        assert_eq!(e.key, TRANSFER_KEY);
        assert!(e
            .message
            .starts_with("unknown transfer 'flip'; valid: shepard,"));
    }
}
