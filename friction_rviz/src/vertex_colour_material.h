// The material both displays draw with: unlit, two-sided, coloured per vertex.
#pragma once

#include <OGRE/OgreMaterialManager.h>
#include <OGRE/OgrePass.h>
#include <OGRE/OgreResourceGroupManager.h>
#include <OGRE/OgreTechnique.h>

#include <string>

namespace friction_rviz {

/// Name of the material in Ogre's default resource group, created on first use.
inline const std::string& vertexColourMaterial() {
  static const std::string name = "friction_rviz/VertexColour";
  auto& manager = Ogre::MaterialManager::getSingleton();
  if (!manager.resourceExists(name, Ogre::ResourceGroupManager::DEFAULT_RESOURCE_GROUP_NAME)) {
    Ogre::MaterialPtr material = manager.create(name, Ogre::ResourceGroupManager::DEFAULT_RESOURCE_GROUP_NAME);
    material->setReceiveShadows(false);
    material->setLightingEnabled(false);
    material->setCullingMode(Ogre::CULL_NONE);
    material->getTechnique(0)->getPass(0)->setVertexColourTracking(Ogre::TVC_AMBIENT | Ogre::TVC_DIFFUSE);
  }
  return name;
}

}  // namespace friction_rviz
