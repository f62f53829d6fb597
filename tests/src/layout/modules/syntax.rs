//! What the walk reads of the syntax tree: the leaves of a `use`, the paths
//! an item names, an item's attributes and name, `#[cfg(test)]` and `#[path]`.

use syn::visit::Visit;

/// `(binding, path)` of every leaf of a use tree; `None` for a glob.
pub fn flatten_use(
    tree: &syn::UseTree,
    prefix: Vec<String>,
    out: &mut Vec<(Option<String>, Vec<String>)>,
) {
    match tree {
        syn::UseTree::Path(p) => {
            let mut next = prefix;
            next.push(p.ident.to_string());
            flatten_use(&p.tree, next, out);
        }
        syn::UseTree::Name(n) => {
            let name = n.ident.to_string();
            let mut path = prefix;
            if name != "self" {
                path.push(name.clone());
            }
            let binding = path.last().cloned();
            out.push((binding, path));
        }
        syn::UseTree::Rename(r) => {
            let mut path = prefix;
            path.push(r.ident.to_string());
            out.push((Some(r.rename.to_string()), path));
        }
        syn::UseTree::Glob(_) => out.push((None, prefix)),
        syn::UseTree::Group(g) => {
            for t in &g.items {
                flatten_use(t, prefix.clone(), out);
            }
        }
    }
}

/// The paths an item names (`crate::`, `super::`, `self::` or with more
/// than one segment), outside nested modules, attributes and test methods.
#[derive(Default)]
pub struct PathCollector {
    /// The paths, as segments.
    pub paths: Vec<Vec<String>>,
}

impl<'ast> Visit<'ast> for PathCollector {
    fn visit_path(&mut self, p: &'ast syn::Path) {
        if let Some(first) = p.segments.first() {
            let f = first.ident.to_string();
            if f == "crate" || f == "super" || f == "self" || p.segments.len() > 1 {
                self.paths
                    .push(p.segments.iter().map(|s| s.ident.to_string()).collect());
            }
        }
        syn::visit::visit_path(self, p);
    }

    fn visit_item_mod(&mut self, _: &'ast syn::ItemMod) {}

    /// `pub(super)` or `pub(in crate::x)` restricts who sees an item; it
    /// names no item of another file.
    fn visit_visibility(&mut self, _: &'ast syn::Visibility) {}

    /// The arguments of a macro call (`println!`, `format!`, `vec!`, ...)
    /// name items too: they are read as comma-separated expressions when
    /// they parse as such (`vec![x; n]` as its two expressions).
    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        use syn::parse::Parser;
        use syn::punctuated::Punctuated;
        let comma = Punctuated::<syn::Expr, syn::Token![,]>::parse_terminated;
        let semi = Punctuated::<syn::Expr, syn::Token![;]>::parse_terminated;
        let exprs: Vec<syn::Expr> = match comma.parse2(m.tokens.clone()) {
            Ok(list) => list.into_iter().collect(),
            Err(_) => semi
                .parse2(m.tokens.clone())
                .map(|l| l.into_iter().collect())
                .unwrap_or_default(),
        };
        for e in &exprs {
            self.visit_expr(e);
        }
        syn::visit::visit_macro(self, m);
    }

    fn visit_attribute(&mut self, _: &'ast syn::Attribute) {}

    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        if !is_test(&f.attrs) {
            syn::visit::visit_impl_item_fn(self, f);
        }
    }
}

/// The attributes of an item.
pub fn attrs_of(item: &syn::Item) -> &[syn::Attribute] {
    match item {
        syn::Item::Const(i) => &i.attrs,
        syn::Item::Enum(i) => &i.attrs,
        syn::Item::Fn(i) => &i.attrs,
        syn::Item::Impl(i) => &i.attrs,
        syn::Item::Macro(i) => &i.attrs,
        syn::Item::Mod(i) => &i.attrs,
        syn::Item::Static(i) => &i.attrs,
        syn::Item::Struct(i) => &i.attrs,
        syn::Item::Trait(i) => &i.attrs,
        syn::Item::Type(i) => &i.attrs,
        syn::Item::Union(i) => &i.attrs,
        syn::Item::Use(i) => &i.attrs,
        _ => &[],
    }
}

/// The name an item defines, if it names one.
pub fn item_name(item: &syn::Item) -> Option<String> {
    Some(match item {
        syn::Item::Const(i) => i.ident.to_string(),
        syn::Item::Enum(i) => i.ident.to_string(),
        syn::Item::Fn(i) => i.sig.ident.to_string(),
        syn::Item::Static(i) => i.ident.to_string(),
        syn::Item::Struct(i) => i.ident.to_string(),
        syn::Item::Trait(i) => i.ident.to_string(),
        syn::Item::Type(i) => i.ident.to_string(),
        syn::Item::Union(i) => i.ident.to_string(),
        syn::Item::Macro(i) => i.ident.as_ref()?.to_string(),
        _ => return None,
    })
}

/// `#[cfg(test)]`, or any `cfg` that names `test`.
pub fn is_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.meta.require_list().is_ok_and(|l| {
                l.tokens
                    .to_string()
                    .split(|c: char| !c.is_alphanumeric() && c != '_')
                    .any(|w| w == "test")
            })
    })
}

/// The file of a `#[path = "…"]` attribute.
pub fn path_attr(attrs: &[syn::Attribute]) -> Option<String> {
    attrs.iter().find_map(|a| {
        let nv = a.meta.require_name_value().ok()?;
        if !a.path().is_ident("path") {
            return None;
        }
        match &nv.value {
            syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) => Some(s.value()),
            _ => None,
        }
    })
}
