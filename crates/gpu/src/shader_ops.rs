//! Counting a lobe's shader instructions for the GPU cost model
//! ([`specula::gpu_cost`]): the exported lobe (constants baked in) is parsed and validated by
//! naga, and the statements of `specula_lobe` and every function it calls are walked, each
//! emitted expression counted once by class. The walk is over naga's IR, from which naga
//! emits SPIR-V one instruction per arithmetic expression. The exported lobe is straight-line
//! code (its squarings written out), so a loop, should one appear, counts its body once. Of
//! an `if`, the costlier branch counts (a divergent warp runs both; a uniform one, at most
//! that).

use naga::{
    BinaryOperator, Block, Expression, Handle, MathFunction, Module, ScalarKind, Statement,
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
        ops
    }
}
