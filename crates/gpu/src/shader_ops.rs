//! Counting a lobe's shader instructions for the GPU cost model
//! ([`specula::gpu_cost`]): the exported lobe (constants baked in) is parsed and validated by
//! naga, and the statements of `specula_lobe` and every function it calls are walked, each
//! emitted expression counted once by class. The walk is over naga's IR, from which naga
//! emits SPIR-V one instruction per arithmetic expression. The exported lobe is straight-line
//! code (its squarings written out), so a loop, should one appear, counts its body once. Of
//! an `if`, the costlier branch counts (a divergent warp runs both; a uniform one, at most
//! that).

use std::sync::OnceLock;

use naga::{
    BinaryOperator, Block, Expression, Handle, MathFunction, Module, ScalarKind, Statement,
    TypeInner,
};
use specula::gpu_cost::ShaderOps;
use specula::{Geometry, Lobe, Normalisation};

use crate::export::export_wgsl_source;
use crate::wgsl;

/// The instructions of `lobe`'s exported shader, per evaluation.
pub fn lobe_shader_ops(lobe: &Lobe) -> Result<ShaderOps, String> {
    let source = export_wgsl_source(lobe, Geometry::Phong, Normalisation::None);
    let (module, info) = wgsl::validate(&source)?;
    let counter = Counter {
        module: &module,
        info: &info,
    };
    let entry = find(&module, "specula_lobe").ok_or("no specula_lobe in the exported shader")?;
    Ok(counter.function(entry))
}

/// The instructions `lobe`'s microfacet BRDF takes per evaluation of its specular term: the
/// lobe ([`lobe_shader_ops`]) and what the microfacet model adds to it, `brdf.wgsl`'s
/// `microfacet_factor` (the normaliser, the two masking-table lookups and `G2`, Schlick's
/// Fresnel per channel, the division by `4 N.wo`). The cosines both take (`N.h`, `wo.h`) are
/// not counted, as they are not for GGX's ([`ggx_microfacet_ops`]); nor are the table's loads,
/// which the cost model, counting arithmetic, leaves out.
pub fn microfacet_shader_ops(lobe: &Lobe) -> Result<ShaderOps, String> {
    // The same function for every lobe: parsed and counted once.
    static FACTOR: OnceLock<Result<ShaderOps, String>> = OnceLock::new();
    let factor = FACTOR.get_or_init(|| function_ops(&wgsl::render_module(), "microfacet_factor"));
    Ok(lobe_shader_ops(lobe)? + factor.clone()?)
}

/// The instructions of GGX's microfacet specular term written as three.js writes it
/// (`shaders/ggx_cost.wgsl`), the peer of [`microfacet_shader_ops`].
pub fn ggx_microfacet_ops() -> Result<ShaderOps, String> {
    function_ops(wgsl::GGX_COST, "ggx_factor")
}

/// The instructions of the function `name` in the WGSL `source`, callees included.
fn function_ops(source: &str, name: &str) -> Result<ShaderOps, String> {
    let (module, info) = wgsl::validate(source)?;
    let counter = Counter {
        module: &module,
        info: &info,
    };
    let entry = find(&module, name).ok_or_else(|| format!("no {name} in the shader"))?;
    Ok(counter.function(entry))
}

fn find(module: &Module, name: &str) -> Option<Handle<naga::Function>> {
    module
        .functions
        .iter()
        .find(|(_, f)| f.name.as_deref() == Some(name))
        .map(|(handle, _)| handle)
}

struct Counter<'a> {
    module: &'a Module,
    info: &'a naga::valid::ModuleInfo,
}

impl Counter<'_> {
    fn function(&self, handle: Handle<naga::Function>) -> ShaderOps {
        self.block(handle, &self.module.functions[handle].body)
    }

    fn block(&self, function: Handle<naga::Function>, block: &Block) -> ShaderOps {
        block.iter().fold(ShaderOps::default(), |sum, statement| {
            sum + self.statement(function, statement)
        })
    }

    fn statement(&self, function: Handle<naga::Function>, statement: &Statement) -> ShaderOps {
        match statement {
            Statement::Emit(range) => range.clone().fold(ShaderOps::default(), |sum, e| {
                sum + self.expression(function, e)
            }),
            Statement::Block(block) => self.block(function, block),
            Statement::If { accept, reject, .. } => {
                let (a, b) = (self.block(function, accept), self.block(function, reject));
                if a.expanded().total() >= b.expanded().total() {
                    a
                } else {
                    b
                }
            }
            Statement::Loop {
                body, continuing, ..
            } => self.block(function, body) + self.block(function, continuing),
            Statement::Call {
                function: callee, ..
            } => self.function(*callee),
            _ => ShaderOps::default(),
        }
    }

    fn expression(
        &self,
        function: Handle<naga::Function>,
        handle: Handle<Expression>,
    ) -> ShaderOps {
        let f = &self.module.functions[function];
        let is_float = || {
            self.info[function][handle]
                .ty
                .inner_with(&self.module.types)
                .scalar_kind()
                == Some(ScalarKind::Float)
        };
        let operand_is_float = |operand: Handle<Expression>| {
            self.info[function][operand]
                .ty
                .inner_with(&self.module.types)
                .scalar_kind()
                == Some(ScalarKind::Float)
        };
        // A vector operation is one instruction per lane on the scalar ALUs GPUs have.
        let lanes = match self.info[function][handle]
            .ty
            .inner_with(&self.module.types)
        {
            TypeInner::Vector { size, .. } => u32::from(*size),
            _ => 1,
        };
        let mut ops = ShaderOps::default();
        match &f.expressions[handle] {
            Expression::Binary { op, left, .. } => match op {
                BinaryOperator::Add | BinaryOperator::Subtract | BinaryOperator::Multiply => {
                    if is_float() {
                        ops.arithmetic = 1;
                    } else {
                        ops.integer = 1;
                    }
                }
                BinaryOperator::Divide => {
                    ops.transcendental = 1;
                    ops.arithmetic = 1;
                }
                BinaryOperator::Less
                | BinaryOperator::LessEqual
                | BinaryOperator::Greater
                | BinaryOperator::GreaterEqual
                | BinaryOperator::Equal
                | BinaryOperator::NotEqual => {
                    if operand_is_float(*left) {
                        ops.compare = 1;
                    } else {
                        ops.integer = 1;
                    }
                }
                _ => ops.integer = 1,
            },
            Expression::Unary { .. } | Expression::Relational { .. } => ops.compare = 1,
            Expression::Select { .. } => ops.compare = 1,
            Expression::As {
                convert: Some(_), ..
            } => ops.conversion = 1,
            Expression::Math { fun, .. } => match fun {
                MathFunction::Exp2 | MathFunction::Log2 | MathFunction::Sqrt => {
                    ops.transcendental = 1;
                }
                MathFunction::InverseSqrt => ops.transcendental = 1,
                MathFunction::Pow => {
                    ops.transcendental = 2;
                    ops.arithmetic = 1;
                }
                MathFunction::Acos => ops.acos = 1,
                MathFunction::Min | MathFunction::Max | MathFunction::Clamp => ops.compare = 1,
                MathFunction::Floor | MathFunction::Ceil | MathFunction::Trunc => {
                    ops.conversion = 1;
                }
                MathFunction::Abs => {}
                _ => ops.arithmetic = 1,
            },
            _ => {}
        }
        ops * lanes
    }
}
